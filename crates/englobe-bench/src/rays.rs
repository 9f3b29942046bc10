//! The three ray sets every library is measured on, generated once per scene from a fixed seed
//! and kept in memory, so that every library traces exactly the same rays.
//!
//! * **primary**: a pinhole camera with a 45 degree field of view framing the mesh's bounding
//!   sphere (centred on the bounding box, through its corners), one ray per pixel centre of a
//!   square image (1024 x 1024 by default). The camera sits on the +z side of the centre at the
//!   distance where the sphere's silhouette is exactly the circle inscribed in the image
//!   (`r / sin(fov / 2)`), looks down -z with +y up. Rays are stored in 4 x 4 pixel blocks (the
//!   blocks in row order, the 16 pixels of a block in row order), so that 16 consecutive rays
//!   form a square packet.
//! * **random**: origins uniform in the bounding box, directions uniform on the unit sphere
//!   (`z = 1 - 2u`, `phi = 2 pi v`): PCG32 started from the seed, three numbers for the
//!   origin, then two for the direction, ray after ray.
//! * **bounce**: from the primary rays' closest hits (found with englobe, which agrees with brute
//!   force exactly), cosine-distributed about the hit triangle's geometric normal turned to face
//!   the incoming ray (Malley's method: a uniform point on the unit disc lifted onto the
//!   hemisphere), leaving from the hit point pushed off the surface along that normal by
//!   `1e-4 * (r + max |centre coordinate|)`, which is far above the rounding error of the hit
//!   point's coordinates. Bounce ray `k` leaves the `(k mod hits)`-th hit in primary order, so
//!   hits are reused evenly when there are fewer hits than rays. The generator is PCG32
//!   started from the bitwise complement of the seed; two numbers per ray.
//!
//! Every direction has unit length and every ray covers `0..=inf`, so that the hit distance `t`
//! means the same for every library.

use std::f32::consts::PI;

use englobe::Vec3;

use crate::library::{BenchRay, RayResult};
use crate::rng::BenchRng;
use crate::scene::BenchScene;

/// The camera's field of view, in degrees.
pub const FIELD_OF_VIEW_DEGREES: f32 = 45.0;
/// Side of the primary image, in pixels, by default.
pub const DEFAULT_RESOLUTION: u32 = 1024;
/// Random and bounce rays, by default: as many as primary rays.
pub const DEFAULT_RAY_COUNT: usize = 1 << 20;
/// The default seed: the year of the report englobe follows.
pub const DEFAULT_SEED: u64 = 2009;
/// Side of the square blocks primary rays are stored in.
pub const BLOCK: u32 = 4;
/// How far bounce rays leave the surface, relative to the scene's size and position.
pub const BOUNCE_OFFSET: f32 = 1e-4;

/// The three sets.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum RaySetKind {
    /// Camera rays.
    Primary,
    /// Uniform origins in the box, uniform directions.
    Random,
    /// Cosine-distributed rays leaving the primary hits.
    Bounce,
}

impl RaySetKind {
    /// All sets, in table order.
    pub const ALL: [RaySetKind; 3] = [RaySetKind::Primary, RaySetKind::Random, RaySetKind::Bounce];

    /// Name in tables and the CSV.
    pub fn name(self) -> &'static str {
        match self {
            RaySetKind::Primary => "primary",
            RaySetKind::Random => "random",
            RaySetKind::Bounce => "bounce",
        }
    }
}

/// What to generate.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct RayParams {
    /// Side of the square primary image (a multiple of [`BLOCK`]).
    pub resolution: u32,
    /// Number of random rays and of bounce rays.
    pub count: usize,
    /// Seed of the random sets.
    pub seed: u64,
}

impl Default for RayParams {
    fn default() -> Self {
        RayParams { resolution: DEFAULT_RESOLUTION, count: DEFAULT_RAY_COUNT, seed: DEFAULT_SEED }
    }
}

/// The pinhole camera that frames a bounding sphere.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FramingCamera {
    /// Eye position.
    pub eye: Vec3,
    /// `tan(fov / 2)`: the image plane at distance 1 spans `-tan..tan` on both axes.
    pub tan_half_fov: f32,
}

impl FramingCamera {
    /// The camera on the +z side of `centre` whose image's inscribed circle is the silhouette of
    /// the sphere `(centre, radius)`.
    pub fn framing(centre: Vec3, radius: f32) -> Self {
        let half = 0.5 * FIELD_OF_VIEW_DEGREES.to_radians();
        FramingCamera { eye: centre + Vec3::Z * (radius / half.sin()), tan_half_fov: half.tan() }
    }

    /// The ray through the centre of pixel `(x, y)` (y down) of a `size x size` image.
    pub fn ray(&self, x: u32, y: u32, size: u32) -> BenchRay {
        let sx = (2.0 * (x as f32 + 0.5) / size as f32 - 1.0) * self.tan_half_fov;
        let sy = (1.0 - 2.0 * (y as f32 + 0.5) / size as f32) * self.tan_half_fov;
        BenchRay::new(self.eye, Vec3::new(sx, sy, -1.0).normalize())
    }
}

/// The pixel of the `i`-th primary ray: blocks of [`BLOCK`] x [`BLOCK`] in row order, pixels
/// within a block in row order.
pub fn primary_pixel(i: usize, size: u32) -> (u32, u32) {
    let per_block = (BLOCK * BLOCK) as usize;
    let blocks_per_row = (size / BLOCK) as usize;
    let (block, within) = (i / per_block, i % per_block);
    let (bx, by) = (block % blocks_per_row, block / blocks_per_row);
    let x = bx as u32 * BLOCK + within as u32 % BLOCK;
    let y = by as u32 * BLOCK + within as u32 / BLOCK;
    (x, y)
}

/// The primary rays: `size * size` of them, in block order.
pub fn primary_rays(scene: &BenchScene, size: u32) -> Vec<BenchRay> {
    assert!(size > 0 && size.is_multiple_of(BLOCK), "the primary image side must be a multiple of {BLOCK}");
    let (centre, radius) = scene.bounding_sphere();
    let camera = FramingCamera::framing(centre, radius);
    (0..(size as usize * size as usize))
        .map(|i| {
            let (x, y) = primary_pixel(i, size);
            match &scene.view {
                Some(view) => view_ray(view, x, y, size),
                None => camera.ray(x, y, size),
            }
        })
        .collect()
}

/// The ray through the centre of pixel `(x, y)` (y down) of a `size x size` image seen from
/// `view`.
pub fn view_ray(view: &crate::scene::View, x: u32, y: u32, size: u32) -> BenchRay {
    let right = view.dir.cross(Vec3::Y).normalize();
    let up = right.cross(view.dir);
    let tan = (0.5 * view.fov_degrees.to_radians()).tan();
    let sx = (2.0 * (x as f32 + 0.5) / size as f32 - 1.0) * tan;
    let sy = (1.0 - 2.0 * (y as f32 + 0.5) / size as f32) * tan;
    BenchRay::new(view.eye, (view.dir + right * sx + up * sy).normalize())
}

/// A uniform direction on the unit sphere from two uniform numbers in `[0, 1)`.
pub fn uniform_direction(u: f32, v: f32) -> Vec3 {
    let z = 1.0 - 2.0 * u;
    let r = (1.0 - z * z).max(0.0).sqrt();
    let phi = 2.0 * PI * v;
    Vec3::new(r * phi.cos(), r * phi.sin(), z).normalize()
}

/// The random rays.
pub fn random_rays(scene: &BenchScene, count: usize, seed: u64) -> Vec<BenchRay> {
    let b = scene.bounds();
    let mut rng = BenchRng::new(seed);
    (0..count)
        .map(|_| {
            let o = Vec3::new(rng.next_f32(), rng.next_f32(), rng.next_f32());
            let origin = b.min + (b.max - b.min) * o;
            let (u, v) = (rng.next_f32(), rng.next_f32());
            BenchRay::new(origin, uniform_direction(u, v))
        })
        .collect()
}

/// Two unit vectors that make an orthonormal basis with the unit vector `n` (Duff, Burgess,
/// Christensen, Hery, Kensler, Liani and Villemin 2017, "Building an Orthonormal Basis,
/// Revisited", JCGT 6(1)).
pub fn orthonormal_basis(n: Vec3) -> (Vec3, Vec3) {
    let sign = 1.0f32.copysign(n.z);
    let a = -1.0 / (sign + n.z);
    let b = n.x * n.y * a;
    (Vec3::new(1.0 + sign * n.x * n.x * a, sign * b, -sign * n.x), Vec3::new(b, sign + n.y * n.y * a, -n.y))
}

/// A cosine-distributed direction about the unit vector `n` from two uniform numbers.
pub fn cosine_direction(n: Vec3, u: f32, v: f32) -> Vec3 {
    let (t, b) = orthonormal_basis(n);
    let r = u.sqrt();
    let phi = 2.0 * PI * v;
    let z = (1.0 - u).max(0.0).sqrt();
    (t * (r * phi.cos()) + b * (r * phi.sin()) + n * z).normalize()
}

/// Distance bounce rays leave the surface by, for this scene.
pub fn bounce_offset(scene: &BenchScene) -> f32 {
    let (centre, radius) = scene.bounding_sphere();
    BOUNCE_OFFSET * (radius + centre.abs().max_element())
}

/// The geometric normal of triangle `prim` turned against `dir` (facing where the ray came from).
pub fn facing_normal(scene: &BenchScene, prim: u32, dir: Vec3) -> Vec3 {
    let n = scene.mesh.geometric_normal(prim);
    if n == Vec3::ZERO {
        -dir
    } else if n.dot(dir) > 0.0 {
        -n
    } else {
        n
    }
}

/// The bounce rays, from the primary rays and their closest hits (`hits[i]` for `primary[i]`).
/// Empty if no primary ray hits anything.
pub fn bounce_rays(
    scene: &BenchScene,
    primary: &[BenchRay],
    hits: &[RayResult],
    count: usize,
    seed: u64,
) -> Vec<BenchRay> {
    let hit_rays: Vec<usize> = (0..primary.len()).filter(|&i| hits[i].is_hit()).collect();
    if hit_rays.is_empty() {
        return Vec::new();
    }
    let offset = bounce_offset(scene);
    let mut rng = BenchRng::new(!seed);
    (0..count)
        .map(|k| {
            let i = hit_rays[k % hit_rays.len()];
            let (ray, hit) = (&primary[i], hits[i]);
            let n = facing_normal(scene, hit.prim, ray.dir);
            let (u, v) = (rng.next_f32(), rng.next_f32());
            BenchRay::new(ray.at(hit.t) + n * offset, cosine_direction(n, u, v))
        })
        .collect()
}

/// The three sets of one scene.
#[derive(Clone, Debug)]
pub struct RaySets {
    /// Camera rays.
    pub primary: Vec<BenchRay>,
    /// Uniform rays.
    pub random: Vec<BenchRay>,
    /// Bounce rays.
    pub bounce: Vec<BenchRay>,
    /// Fraction of the primary rays that hit the mesh.
    pub primary_hit_fraction: f64,
}

impl RaySets {
    /// The set `kind`.
    pub fn get(&self, kind: RaySetKind) -> &[BenchRay] {
        match kind {
            RaySetKind::Primary => &self.primary,
            RaySetKind::Random => &self.random,
            RaySetKind::Bounce => &self.bounce,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn blocks_cover_the_image_once() {
        let size = 16;
        let mut seen = vec![false; 256];
        for i in 0..256 {
            let (x, y) = primary_pixel(i, size);
            assert!(!std::mem::replace(&mut seen[(y * size + x) as usize], true));
        }
        assert_eq!(primary_pixel(0, size), (0, 0));
        assert_eq!(primary_pixel(5, size), (1, 1));
        assert_eq!(primary_pixel(15, size), (3, 3));
        assert_eq!(primary_pixel(16, size), (4, 0));
        assert_eq!(primary_pixel(64, size), (0, 4));
    }

    #[test]
    fn bases_are_orthonormal() {
        let mut rng = BenchRng::new(1);
        for _ in 0..10_000 {
            let n = uniform_direction(rng.next_f32(), rng.next_f32());
            let (t, b) = orthonormal_basis(n);
            for (x, y) in [(t, b), (t, n), (b, n)] {
                assert!(x.dot(y).abs() < 1e-5);
            }
            assert!((t.length() - 1.0).abs() < 1e-5 && (b.length() - 1.0).abs() < 1e-5);
        }
    }

    #[test]
    fn cosine_directions_have_the_cosine_mean() {
        // E[cos] = 2/3 for a cosine-weighted hemisphere.
        let mut rng = BenchRng::new(3);
        let n = Vec3::new(0.3, -0.5, 0.8).normalize();
        let count = 200_000;
        let mean: f32 = (0..count)
            .map(|_| {
                let d = cosine_direction(n, rng.next_f32(), rng.next_f32());
                assert!(d.dot(n) >= 0.0);
                d.dot(n)
            })
            .sum::<f32>()
            / count as f32;
        assert!((mean - 2.0 / 3.0).abs() < 0.005, "{mean}");
    }
}
