//! Triangles, with the watertight ray/triangle test of Woop, Benthin and Wald (2013),
//! "Watertight Ray/Triangle Intersection" (JCGT 2(1)).
//!
//! The vertices are moved into a frame where the ray runs along +z from the origin; the test then
//! reduces to 2D edge functions evaluated with the same operations, in the same order, for the two
//! triangles that share an edge, so a ray through a shared edge or vertex can never slip between
//! them. When an edge function comes out exactly zero the paper recomputes it in `f64` so that the
//! sign decision on an edge is exact; we finish the whole test in `f64` then, and also when an edge
//! function underflows or overflows `f32` (scenes scaled far below or above 1), so that the answer
//! does not depend on the scene's scale. A zero-area triangle has a zero determinant and is never hit.
//! A hit is kept within the stretch of the ray that lies inside the triangle's box (see
//! [`intersect_triangle`]), so that structures which prune by boxes agree with brute force.

use glam::Vec3;

use super::{Bounded, Intersect};
use crate::PrimHit;
use crate::geom::aabb::ROBUST_FAR_SCALE;
use crate::{Aabb, Ray};

/// A triangle given by its three vertices.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Triangle {
    /// The vertices, counter-clockwise around the normal.
    pub vertices: [Vec3; 3],
}

impl Triangle {
    /// A triangle.
    pub fn new(a: Vec3, b: Vec3, c: Vec3) -> Self {
        Triangle { vertices: [a, b, c] }
    }

    /// Twice the area (in `f32`, so it can underflow for tiny triangles: use
    /// [`Triangle::is_degenerate`] to ask whether there is any area at all).
    pub fn double_area(&self) -> f32 {
        let [a, b, c] = self.vertices;
        (b - a).cross(c - a).length()
    }

    /// True if the vertices lie on one line (see [`is_degenerate`]): such a triangle is never hit.
    pub fn is_degenerate(&self) -> bool {
        let [a, b, c] = self.vertices;
        is_degenerate(a, b, c)
    }
}

/// The six orders `[kx, ky, kz]` [`WatertightRay::axes_of`] chooses from, two bits per axis, six
/// bits per order, in the order of [`WatertightRay::axes_code`]: a shift instead of a load.
const AXES: u64 = pack([1, 2, 0])
    | pack([2, 1, 0]) << 6
    | pack([2, 0, 1]) << 12
    | pack([0, 2, 1]) << 18
    | pack([0, 1, 2]) << 24
    | pack([1, 0, 2]) << 30;

const fn pack(axes: [u64; 3]) -> u64 {
    axes[0] | axes[1] << 2 | axes[2] << 4
}

/// The per-ray constants of the watertight test: the axis the ray runs along (`kz`), the two
/// others (`kx`, `ky`, swapped to keep the winding), and the shear that maps the ray onto +z.
#[derive(Clone, Copy, Debug)]
pub struct WatertightRay {
    kx: usize,
    ky: usize,
    kz: usize,
    shear: Vec3,
}

impl WatertightRay {
    /// The six orders of axes (see [`WatertightRay::axes_code`]), two bits per axis, six bits
    /// per order, for code that unpacks them in its own form.
    pub(crate) const AXES: u64 = AXES;

    /// The constants for `ray`.
    #[inline(always)]
    pub fn new(ray: &Ray) -> Self {
        let d = ray.dir();
        let [kx, ky, kz] = Self::axes_of(d);
        // An array, not the vector: `Vec3`'s index is a chain of comparisons per lookup.
        let d = d.to_array();
        let shear = Vec3::new(d[kx] / d[kz], d[ky] / d[kz], 1.0 / d[kz]);
        WatertightRay { kx, ky, kz, shear }
    }

    /// The axes `[kx, ky, kz]` of a ray of direction `d` (see [`WatertightRay::axes`]), without
    /// the shear.
    #[inline(always)]
    pub fn axes_of(d: Vec3) -> [usize; 3] {
        let bits = Self::AXES >> (6 * Self::axes_code(d));
        [(bits & 3) as usize, (bits >> 2 & 3) as usize, (bits >> 4 & 3) as usize]
    }

    /// Which of the six orders [`WatertightRay::axes_of`] gives for a ray of direction `d`:
    /// `2 * kz + down`, `down` being 1 if the ray goes down `kz`.
    #[inline(always)]
    pub(crate) fn axes_code(d: Vec3) -> u32 {
        // `kz` is the axis of the largest component (the first of equal ones); `kx, ky` follow it
        // cyclically, swapped if the ray goes down `kz` so that the triangles' winding is kept.
        // Computed without branches: the axis of a random ray is a coin toss that a branch
        // predictor loses half the time.
        let a = d.abs();
        let x_largest = (a.x >= a.y) & (a.x >= a.z);
        let kz = (!x_largest as u32) * (1 + !(a.y >= a.z) as u32);
        let down = d.cmplt(Vec3::ZERO).bitmask() >> kz & 1;
        2 * kz + down
    }

    /// The axes `[kx, ky, kz]`: the ray runs along `kz` in the sheared frame.
    #[inline(always)]
    pub fn axes(&self) -> [usize; 3] {
        [self.kx, self.ky, self.kz]
    }

    /// The shear `(d[kx] / d[kz], d[ky] / d[kz], 1 / d[kz])`.
    #[inline(always)]
    pub fn shear(&self) -> Vec3 {
        self.shear
    }
}

/// The watertight test of `ray` against the triangle `v0 v1 v2`, with the ray's constants `w`.
/// Returns `t` within the ray's interval and the barycentric weights `(u, v)` of `v1` and `v2`.
/// Both sides of the triangle are hit.
#[inline(always)]
pub fn intersect_triangle(ray: &Ray, w: &WatertightRay, v0: Vec3, v1: Vec3, v2: Vec3) -> Option<PrimHit> {
    let o = ray.origin();
    let (a, b, c) = (v0 - o, v1 - o, v2 - o);
    let (sx, sy, sz) = (w.shear.x, w.shear.y, w.shear.z);
    let ax = a[w.kx] - sx * a[w.kz];
    let ay = a[w.ky] - sy * a[w.kz];
    let bx = b[w.kx] - sx * b[w.kz];
    let by = b[w.ky] - sy * b[w.kz];
    let cx = c[w.kx] - sx * c[w.kz];
    let cy = c[w.ky] - sy * c[w.kz];

    let az = sz * a[w.kz];
    let bz = sz * b[w.kz];
    let cz = sz * c[w.kz];
    let projected = Projected { ax, ay, az, bx, by, bz, cx, cy, cz };

    let e0 = cx * by - cy * bx;
    let e1 = ax * cy - ay * cx;
    let e2 = bx * ay - by * ax;
    // An edge function that is exactly zero (a ray through an edge or vertex) is where rounding
    // could let a ray slip between two triangles: the paper recomputes it in double precision
    // from the same projected vertices. We do the rest of the test in double precision too, and
    // also when an edge function underflowed (subnormal) or overflowed, so that scenes at any
    // scale `f32` can hold give the same answers. Rounding is monotonic, so an `f32` edge
    // function is either zero or of the right sign, and the triangle on the other side of a
    // shared edge sees the same value: the two triangles never disagree.
    if !(e0.is_normal() && e1.is_normal() && e2.is_normal()) {
        return projected.intersect_f64().and_then(|hit| finish(ray, hit, v0, v1, v2));
    }
    if (e0 < 0.0 || e1 < 0.0 || e2 < 0.0) && (e0 > 0.0 || e1 > 0.0 || e2 > 0.0) {
        return None;
    }
    let det = e0 + e1 + e2;
    let t_scaled = e0 * az + e1 * bz + e2 * cz;
    let inv_det = 1.0 / det;
    let t = t_scaled * inv_det;
    if !t.is_finite() {
        return projected.intersect_f64().and_then(|hit| finish(ray, hit, v0, v1, v2));
    }
    finish(ray, PrimHit { t, u: e1 * inv_det, v: e2 * inv_det }, v0, v1, v2)
}

/// The last steps of a hit found by the edge functions: its `t` brought into the stretch of the
/// ray inside the triangle's box, then the ray's interval and the zero-area rule applied.
///
/// The hit lies on the triangle, so within its box. On a long thin triangle the edge functions
/// lose digits to cancellation, and `t` can come out of that stretch (by 2e-5 relative on the
/// slivers of the Sponza atrium): a structure that skips boxes the ray enters beyond the closest
/// hit would then disagree with one that tests everything. So `t` is moved into the stretch,
/// computed as every structure computes it (the far end widened for rounding) before the ray's
/// interval is applied; the true `t` lies in it, so this only moves `t` nearer the truth. A box
/// the robust slab test says the ray misses is truly missed.
#[inline(always)]
fn finish(ray: &Ray, hit: PrimHit, v0: Vec3, v1: Vec3, v2: Vec3) -> Option<PrimHit> {
    let whole_line = ray.with_range(f32::NEG_INFINITY, f32::INFINITY);
    let (enter, exit) = Aabb::from_points([v0, v1, v2]).slab_distances(&whole_line, ROBUST_FAR_SCALE);
    if !(enter <= exit) {
        return None;
    }
    let t = if hit.t < enter {
        enter
    } else if hit.t > exit {
        exit
    } else {
        hit.t
    };
    if !(t >= ray.t_min && t <= ray.t_max) || is_degenerate(v0, v1, v2) {
        return None;
    }
    Some(PrimHit { t, ..hit })
}

/// True if the triangle has no area: its three vertices lie exactly on one line (or coincide).
/// Decided in `f64`, where the differences of `f32` coordinates are exact and the cross product
/// rounds once, so the answer does not depend on the triangle's scale. The mesh loaders drop
/// triangles by this rule; the intersection test applies it on its (rare) hit path, because the
/// shear can round the projected vertices of such a triangle off their common line.
#[inline]
pub fn is_degenerate(v0: Vec3, v1: Vec3, v2: Vec3) -> bool {
    let (a, b, c) = (v0.as_dvec3(), v1.as_dvec3(), v2.as_dvec3());
    (b - a).cross(c - a) == glam::DVec3::ZERO
}

/// The three vertices in the ray's sheared frame, as the single-precision test computed them.
struct Projected {
    ax: f32,
    ay: f32,
    az: f32,
    bx: f32,
    by: f32,
    bz: f32,
    cx: f32,
    cy: f32,
    cz: f32,
}

impl Projected {
    /// The rest of the test in `f64`: the products of two `f32` values are exact there, so edge
    /// functions have the right sign, and neither underflow nor overflow for any `f32` scene. A
    /// zero-area triangle still has a zero determinant and is never hit. The ray's interval is
    /// applied by the caller.
    #[cold]
    #[inline(never)]
    fn intersect_f64(&self) -> Option<PrimHit> {
        let f = |x: f32| x as f64;
        let (ax, ay, az, bx, by, bz, cx, cy, cz) = (
            f(self.ax),
            f(self.ay),
            f(self.az),
            f(self.bx),
            f(self.by),
            f(self.bz),
            f(self.cx),
            f(self.cy),
            f(self.cz),
        );
        let e0 = cx * by - cy * bx;
        let e1 = ax * cy - ay * cx;
        let e2 = bx * ay - by * ax;
        if (e0 < 0.0 || e1 < 0.0 || e2 < 0.0) && (e0 > 0.0 || e1 > 0.0 || e2 > 0.0) {
            return None;
        }
        let det = e0 + e1 + e2;
        if det == 0.0 || !det.is_finite() {
            return None;
        }
        let t = ((e0 * az + e1 * bz + e2 * cz) / det) as f32;
        if !t.is_finite() {
            return None;
        }
        Some(PrimHit { t, u: (e1 / det) as f32, v: (e2 / det) as f32 })
    }
}

impl Bounded for Triangle {
    fn bounds(&self) -> Aabb {
        Aabb::from_points(self.vertices)
    }
}

impl Intersect for Triangle {
    #[inline]
    fn intersect(&self, ray: &Ray) -> Option<PrimHit> {
        let [a, b, c] = self.vertices;
        intersect_triangle(ray, &WatertightRay::new(ray), a, b, c)
    }

    fn normal(&self, _p: Vec3, _hit: &PrimHit) -> Vec3 {
        let [a, b, c] = self.vertices;
        (b - a).cross(c - a).normalize_or_zero()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn tri() -> Triangle {
        Triangle::new(Vec3::ZERO, Vec3::X, Vec3::Y)
    }

    #[test]
    fn hit_inside_gives_barycentrics() {
        let hit = tri().intersect(&Ray::new(Vec3::new(0.25, 0.5, 2.0), -Vec3::Z)).unwrap();
        assert_eq!(hit.t, 2.0);
        assert!((hit.u - 0.25).abs() < 1e-6 && (hit.v - 0.5).abs() < 1e-6);
        assert_eq!(tri().normal(Vec3::ZERO, &hit), Vec3::Z);
    }

    #[test]
    fn the_axes_are_those_of_the_paper() {
        // Woop, Benthin and Wald's choice, written with branches, against the table, on every
        // direction made of these components: ties, zeros of both signs, infinities, NaN.
        let reference = |d: Vec3| {
            let a = d.abs();
            let kz = if a.x >= a.y && a.x >= a.z {
                0
            } else if a.y >= a.z {
                1
            } else {
                2
            };
            let (kx, ky) = ((kz + 1) % 3, (kz + 2) % 3);
            if d[kz] < 0.0 { [ky, kx, kz] } else { [kx, ky, kz] }
        };
        let values = [0.0f32, -0.0, 1.0, -1.0, 0.5, -2.0, f32::INFINITY, f32::NEG_INFINITY, f32::NAN];
        for x in values {
            for y in values {
                for z in values {
                    let d = Vec3::new(x, y, z);
                    assert_eq!(WatertightRay::axes_of(d), reference(d), "{d:?}");
                }
            }
        }
    }

    #[test]
    fn both_sides_are_hit() {
        assert!(tri().intersect(&Ray::new(Vec3::new(0.2, 0.2, -1.0), Vec3::Z)).is_some());
    }

    #[test]
    fn ray_on_an_edge_and_a_vertex_hits() {
        // On the edge x = 0, and exactly on vertex (1, 0, 0).
        assert!(tri().intersect(&Ray::new(Vec3::new(0.0, 0.5, 1.0), -Vec3::Z)).is_some());
        assert!(tri().intersect(&Ray::new(Vec3::new(1.0, 0.0, 1.0), -Vec3::Z)).is_some());
        // On the hypotenuse x + y = 1.
        assert!(tri().intersect(&Ray::new(Vec3::new(0.5, 0.5, 1.0), -Vec3::Z)).is_some());
        assert!(tri().intersect(&Ray::new(Vec3::new(0.5, 0.5001, 1.0), -Vec3::Z)).is_none());
    }

    #[test]
    fn shared_edge_is_hit_by_exactly_one_or_both_never_neither() {
        // Two triangles sharing the diagonal of the unit square; rays along the diagonal.
        let t1 = Triangle::new(Vec3::ZERO, Vec3::X, Vec3::new(1.0, 1.0, 0.0));
        let t2 = Triangle::new(Vec3::ZERO, Vec3::new(1.0, 1.0, 0.0), Vec3::Y);
        for i in 0..=1000 {
            let s = i as f32 / 1000.0;
            let o = Vec3::new(s, s, 3.0);
            let d = Vec3::new(0.1 * s, -0.07, -1.0);
            let ray = Ray::new(o - d * 0.0, d);
            let p = ray.origin() + ray.dir() * 3.0;
            let inside = (0.0..=1.0).contains(&p.x) && (0.0..=1.0).contains(&p.y);
            if inside {
                assert!(t1.intersect(&ray).is_some() || t2.intersect(&ray).is_some(), "slipped at {s}");
            }
        }
    }

    #[test]
    fn degenerate_triangles_are_never_hit() {
        let flat = Triangle::new(Vec3::ZERO, Vec3::X, Vec3::X * 2.0);
        let point = Triangle::new(Vec3::ONE, Vec3::ONE, Vec3::ONE);
        for ray in [
            Ray::new(Vec3::new(0.5, 0.0, 1.0), -Vec3::Z),
            Ray::new(Vec3::new(-1.0, 0.0, 0.0), Vec3::X),
            Ray::new(Vec3::new(1.0, 1.0, 3.0), -Vec3::Z),
        ] {
            assert!(flat.intersect(&ray).is_none());
            assert!(point.intersect(&ray).is_none());
        }
        assert_eq!(flat.double_area(), 0.0);
        assert!(flat.is_degenerate() && point.is_degenerate() && !tri().is_degenerate());
        // Collinear along z, aimed at the middle from afar: the sheared edge functions do not
        // cancel exactly, and the hit they would give lies off the segment, outside its box.
        let on_z = Triangle::new(
            Vec3::new(0.0, 0.0, 8.786655),
            Vec3::new(0.0, 0.0, 5.2886734),
            Vec3::new(0.0, 0.0, 6.1506586),
        );
        let from = Vec3::new(11.242288, -3.151279, -10.5479765);
        assert!(on_z.intersect(&Ray::new(from, on_z.bounds().center() - from)).is_none());
    }

    #[test]
    fn a_sliver_s_hit_lies_in_its_box() {
        // A triangle of the Sponza atrium, 10.8 long and 0.01 wide, seen at a glancing angle: the
        // edge functions alone put the hit 1.4e-4 before the ray enters the triangle's box.
        let sliver = Triangle::new(
            Vec3::new(-10.812759, 5.863311, -2.41851),
            Vec3::new(0.00724, 5.863311, -2.418511),
            Vec3::new(0.00724, 5.873311, -2.426511),
        );
        let ray = Ray::new(Vec3::new(-13.0, 2.0, -0.5), Vec3::new(0.7530834, 0.58926415, -0.29263103));
        let hit = sliver.intersect(&ray).expect("a hit");
        let (enter, exit) = sliver.bounds().intersect(&ray).expect("the box is hit");
        assert!(enter <= hit.t && hit.t <= exit, "{} outside {enter}..={exit}", hit.t);
        // The ray's interval applies to the corrected `t`: ending just before it, no hit.
        assert!(sliver.intersect(&ray.with_range(0.0, enter * 0.999_999)).is_none());
        assert_eq!(sliver.intersect(&ray.with_range(0.0, hit.t)).map(|h| h.t), Some(hit.t));
    }

    #[test]
    fn needles_and_slivers_never_give_nan() {
        // Triangles whose vertices nearly coincide or nearly line up, hit from many directions:
        // any hit has finite t and barycentrics in [0, 1]; exactly collinear ones are never hit.
        let needles = [
            Triangle::new(Vec3::ZERO, Vec3::new(1.0, 1e-7, 0.0), Vec3::new(2.0, 0.0, 0.0)),
            Triangle::new(Vec3::ZERO, Vec3::new(1e-30, 0.0, 0.0), Vec3::new(0.0, 1.0, 0.0)),
            Triangle::new(Vec3::ONE, Vec3::ONE + Vec3::splat(1e-38), Vec3::ONE * 2.0),
            Triangle::new(Vec3::new(1e6, 0.0, 0.0), Vec3::new(1e6 + 0.0625, 0.0, 0.0), Vec3::new(1e6, 1e-3, 1e-3)),
        ];
        let collinear = Triangle::new(Vec3::ZERO, Vec3::new(1.0, 1.0, 1.0), Vec3::new(3.0, 3.0, 3.0));
        for i in 0..2000 {
            let a = i as f32 * 0.618_034;
            let o = Vec3::new(a.sin() * 3.0, (a * 1.3).cos() * 3.0, (a * 0.7).sin() * 3.0 + 0.5);
            for tri in needles.iter().chain([&collinear]) {
                let target = tri.vertices[i % 3] * 0.5 + tri.vertices[(i + 1) % 3] * 0.5;
                let ray = Ray::new(o, target - o);
                if let Some(hit) = tri.intersect(&ray) {
                    assert!(hit.t.is_finite() && hit.u.is_finite() && hit.v.is_finite(), "{tri:?}: {hit:?}");
                    assert!((0.0..=1.0).contains(&hit.u) && (0.0..=1.0).contains(&hit.v), "{tri:?}: {hit:?}");
                }
            }
            assert!(collinear.intersect(&Ray::new(o, collinear.vertices[1] - o)).is_none());
        }
    }

    #[test]
    fn scaled_far_up_or_down_a_triangle_is_hit_the_same() {
        for s in [1e-30f32, 1e-20, 1e-10, 1.0, 1e10, 1e20, 1e30] {
            let t =
                Triangle::new(Vec3::new(0.0, 0.0, 1.0) * s, Vec3::new(1.0, 0.0, 1.0) * s, Vec3::new(0.0, 1.0, 1.0) * s);
            let hit = t.intersect(&Ray::new(Vec3::new(0.25, 0.5, -1.0) * s, Vec3::Z)).expect("hit at every scale");
            assert!((hit.t / s - 2.0).abs() < 1e-6, "scale {s:e}: t = {}", hit.t);
            assert!((hit.u - 0.25).abs() < 1e-6 && (hit.v - 0.5).abs() < 1e-6);
            assert!(t.intersect(&Ray::new(Vec3::new(0.75, 0.5, -1.0) * s, Vec3::Z)).is_none(), "scale {s:e}");
        }
    }

    #[test]
    fn ray_in_the_triangle_plane_misses_without_nan() {
        assert!(tri().intersect(&Ray::new(Vec3::new(-1.0, 0.25, 0.0), Vec3::X)).is_none());
    }

    #[test]
    fn interval_is_respected() {
        let ray = Ray::segment(Vec3::new(0.2, 0.2, 2.0), -Vec3::Z, 0.0, 1.5);
        assert!(tri().intersect(&ray).is_none());
    }

    #[test]
    fn zero_direction_components_give_no_nan() {
        let ray = Ray::new(Vec3::new(0.3, 0.3, 5.0), Vec3::new(-0.0, 0.0, -1.0));
        let hit = tri().intersect(&ray).unwrap();
        assert!(hit.t == 5.0 && hit.u.is_finite() && hit.v.is_finite());
    }
}
