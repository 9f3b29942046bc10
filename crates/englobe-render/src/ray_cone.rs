//! Ray cones: the seed report's "generalised rays", used for texture filtering. A ray stands for
//! a cone (Amanatides 1984, "Ray Tracing with Cones"), the part of the pixel it samples; where it
//! hits a surface the cone covers a patch of it, and the texture is read over that patch instead
//! of at one point, so that a far texture shows its average instead of aliasing between texels.
//! The form is that of Akenine-Möller, Nilsson, Andersson, Barré-Brisebois, Toth and Karras 2019
//! ("Texture Level of Detail Strategies for Real-Time Ray Tracing", *Ray Tracing Gems*, ch. 20):
//! a cone is a width and a spread angle, its width at distance `t` is `width + spread * t`.
//!
//! A camera ray's spread is the angle of one pixel at the eye (the pixel's side on the image plane
//! at distance 1), divided by the square root of the samples per pixel, each sample standing for
//! its share of the pixel's area: the pixel filter averages the samples, the cone the texels
//! within one sample. An orthographic camera's rays are cylinders as wide as a pixel. A lens is
//! left to the samples (its blur is sampled as before), so its rays get the pinhole's cone.
//! Reflected and refracted rays continue the cone from its width at the hit with the same
//! spread: exact for flat mirrors and windows, too narrow behind curved ones (the paper's
//! curvature term is left out).
//!
//! At a hit on a textured triangle the cone's cross-section, a disk of the cone's width across,
//! meets the triangle's plane in an ellipse: half-axes `r / |cos θ|` along the ray's direction
//! projected on the plane and `r` across it (`r` the half-width, `θ` between the ray and the
//! normal). The triangle's texture coordinates map the ellipse's axes into texture space (the
//! linear map that takes its edges to their coordinate differences), and the texture module reads
//! that footprint (englobe-scene's `texture::filtered`: trilinear mip lookups, anisotropic by
//! footprint assembly).

use englobe::{Object, Vec3};
use englobe_scene::texture::UvFootprint;
use englobe_scene::{Camera, Projection, SceneObject};

/// The smallest `|cos θ|` a footprint is computed with: at grazing angles the ellipse grows
/// without bound, and the texture module's anisotropy cap decides what is read anyway.
const MIN_COS: f32 = 1e-4;

/// A cone around a ray: its width at the ray's origin and the growth of the width per unit of
/// distance (the spread angle, small enough that its tangent is itself).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RayCone {
    /// Width (diameter) at the origin.
    pub width: f32,
    /// Width gained per unit of distance.
    pub spread: f32,
}

impl RayCone {
    /// The cone of every camera ray of `camera` for an image `height` pixels high at `samples`
    /// per pixel.
    pub fn primary(camera: &Camera, height: u32, samples: u32) -> Self {
        let share = 1.0 / (samples.max(1) as f32).sqrt();
        match camera.projection {
            Projection::Perspective => {
                let pixel = 2.0 * (camera.fov_degrees.to_radians() * 0.5).tan() / height as f32;
                RayCone { width: 0.0, spread: pixel * share }
            }
            Projection::Orthographic { view_height } => {
                RayCone { width: view_height / height as f32 * share, spread: 0.0 }
            }
        }
    }

    /// The width at distance `t` from the origin.
    #[inline]
    pub fn width_at(&self, t: f32) -> f32 {
        self.width + self.spread * t
    }

    /// The cone of a ray leaving a flat surface hit at distance `t` (a mirror's reflection, a
    /// window's refraction).
    #[inline]
    pub fn continued(&self, t: f32) -> Self {
        RayCone { width: self.width_at(t), spread: self.spread }
    }
}

/// The footprint in texture coordinate set `set` (0 or 1) of a cone `width` wide arriving along
/// the unit direction `d` on triangle `prim` of `object` (a mesh, or an instance of one); `None`
/// for shapes, meshes without that set, and degenerate triangles or coordinates. Each set has
/// its own: the same patch of surface covers more or less of the image depending on how much of
/// it a set spreads over the triangle.
pub fn footprint(object: &SceneObject, set: u32, prim: u32, d: Vec3, width: f32) -> Option<UvFootprint> {
    let (mesh, to_world) = match &object.object {
        Object::Mesh(m) => (&**m, None),
        Object::Instance(i) => (&**i.mesh(), Some(i.to_world())),
        Object::Shape(_) => return None,
    };
    let uvs = mesh.uv_set(set)?;
    let tri = *mesh.triangles().get(prim as usize)?;
    let p = tri.map(|i| {
        let p = mesh.positions()[i as usize];
        to_world.map_or(p, |m| m.transform_point3(p))
    });
    let t = tri.map(|i| uvs[i as usize]);
    let (e1, e2) = (p[1] - p[0], p[2] - p[0]);
    let (t1, t2) = (t[1] - t[0], t[2] - t[0]);
    let n = e1.cross(e2).try_normalize()?;
    let cos = d.dot(n).abs().max(MIN_COS);
    let r = width * 0.5;
    let along = d - n * d.dot(n);
    let major_dir = along.try_normalize().or_else(|| e1.try_normalize())?;
    let major = major_dir * (r / cos);
    let minor = n.cross(major_dir) * r;
    // A vector of the plane as a combination of the edges (by the normal equations), and the
    // same combination of their texture-coordinate differences.
    let (g11, g12, g22) = (e1.dot(e1), e1.dot(e2), e2.dot(e2));
    let det = g11 * g22 - g12 * g12;
    if !(det > 0.0) {
        return None;
    }
    let to_uv = |a: Vec3| {
        let (b1, b2) = (e1.dot(a), e2.dot(a));
        t1 * ((g22 * b1 - g12 * b2) / det) + t2 * ((g11 * b2 - g12 * b1) / det)
    };
    let axes = [to_uv(major), to_uv(minor)];
    axes.iter().all(|a| a.is_finite()).then_some(UvFootprint { axes })
}

#[cfg(test)]
mod tests {
    use std::sync::Arc;

    use englobe::{Affine3A, Instance, TriangleMesh, Vec2};
    use englobe_scene::texture::FilterPlan;

    use super::*;

    /// A square of side `side` in the plane z = 0 facing -z, its texture coordinates 0..1.
    fn square(side: f32) -> TriangleMesh {
        let p = [[0.0, 0.0, 0.0], [side, 0.0, 0.0], [side, side, 0.0], [0.0, side, 0.0]].map(Vec3::from);
        TriangleMesh::new(p.to_vec(), vec![[0, 1, 2], [0, 2, 3]])
            .unwrap()
            .with_uvs([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]].map(Vec2::from).to_vec())
            .unwrap()
    }

    #[test]
    fn head_on_the_level_is_log2_of_distance_angle_and_texels() {
        // A plane 10 units from a camera of 60 degrees and 200 rows, seen head-on, textured with
        // a 1024-texel image over 4 units: 256 texels per unit.
        let camera = Camera::pinhole(Vec3::ZERO, Vec3::Z, Vec3::Y, 60.0);
        let cone = RayCone::primary(&camera, 200, 1);
        let a = 2.0 * 30f32.to_radians().tan() / 200.0;
        assert!((cone.spread - a).abs() < 1e-9);
        let object = SceneObject::new(Object::Mesh(Arc::new(square(4.0))), 0);
        for d in [10.0f32, 3.0, 50.0] {
            let f = footprint(&object, 0, 1, Vec3::Z, cone.width_at(d)).unwrap();
            let plan = FilterPlan::new(f, 1024, 1024).unwrap();
            let expected = (d * a * 256.0).log2();
            assert_eq!(plan.probes, 1);
            assert!((plan.lod - expected).abs() < 1e-4, "{d}: {} against {expected}", plan.lod);
        }
        // Four samples per pixel: each stands for a quarter of the pixel, one level finer.
        let four = RayCone::primary(&camera, 200, 4);
        assert!((four.spread * 2.0 - a).abs() < 1e-9);
    }

    #[test]
    fn a_tilted_plane_stretches_the_footprint_along_the_ray() {
        // Seen at 60 degrees from its normal, the ellipse is twice as long along the ray's
        // projection (x here) as across it (y).
        let object = SceneObject::new(Object::Mesh(Arc::new(square(1.0))), 0);
        let d = Vec3::new(60f32.to_radians().sin(), 0.0, 60f32.to_radians().cos());
        let f = footprint(&object, 0, 0, d, 0.1).unwrap();
        assert!((f.axes[0] - Vec2::new(0.1, 0.0)).length() < 1e-5, "{:?}", f.axes);
        assert!((f.axes[1].abs() - Vec2::new(0.0, 0.05)).length() < 1e-5, "{:?}", f.axes);
        // An instance scaled by 2 halves the footprint in texture coordinates.
        let inst = Instance::new(Arc::new(square(1.0)), Affine3A::from_scale(Vec3::splat(2.0))).unwrap();
        let object = SceneObject::new(Object::Instance(inst), 0);
        let f = footprint(&object, 0, 0, Vec3::Z, 0.1).unwrap();
        assert!((f.axes[0].length() - 0.025).abs() < 1e-6 && (f.axes[1].length() - 0.025).abs() < 1e-6);
    }

    #[test]
    fn each_coordinate_set_has_its_own_footprint() {
        // Set 1 spreads a quarter of the image over the square (a light map's tile, say): its
        // footprint is a quarter of set 0's; a mesh without set 1 has no footprint there.
        let one = square(1.0);
        assert!(footprint(&SceneObject::new(Object::Mesh(Arc::new(one.clone())), 0), 1, 0, Vec3::Z, 0.1).is_none());
        let quarter = one.uvs().unwrap().iter().map(|uv| *uv * 0.25).collect();
        let object = SceneObject::new(Object::Mesh(Arc::new(one.with_uvs1(quarter).unwrap())), 0);
        let f0 = footprint(&object, 0, 0, Vec3::Z, 0.1).unwrap();
        let f1 = footprint(&object, 1, 0, Vec3::Z, 0.1).unwrap();
        for k in 0..2 {
            assert!((f0.axes[k].length() - 0.05).abs() < 1e-6, "{:?}", f0.axes);
            assert!((f1.axes[k].length() - 0.0125).abs() < 1e-6, "{:?}", f1.axes);
        }
    }

    #[test]
    fn cones_grow_and_continue() {
        let ortho = Camera {
            projection: Projection::Orthographic { view_height: 4.0 },
            ..Camera::pinhole(Vec3::ZERO, Vec3::Z, Vec3::Y, 60.0)
        };
        let c = RayCone::primary(&ortho, 100, 16);
        assert_eq!((c.width, c.spread), (0.01, 0.0));
        let c = RayCone { width: 0.5, spread: 0.25 };
        assert_eq!(c.width_at(2.0), 1.0);
        assert_eq!(c.continued(2.0).width_at(2.0), 1.5);
    }
}
