//! The two-sided ray/triangle test of Möller and Trumbore (1997), "Fast, Minimum Storage
//! Ray/Triangle Intersection" (Journal of Graphics Tools 2(1)), for the `bvh` crate's adapter:
//! that crate ships only a variant that culls back faces, and every other library here hits both
//! sides. It is not watertight: a ray through a shared edge can slip between two triangles, which
//! the agreement check counts.

use englobe::Vec3;

/// The distance at which the ray `origin + t * dir` hits triangle `v0 v1 v2` within
/// `t_min..=t_max`, from either side.
#[inline(always)]
pub fn intersect(origin: Vec3, dir: Vec3, t_min: f32, t_max: f32, [v0, v1, v2]: [Vec3; 3]) -> Option<f32> {
    let e1 = v1 - v0;
    let e2 = v2 - v0;
    let p = dir.cross(e2);
    let det = e1.dot(p);
    if det == 0.0 {
        return None;
    }
    let inv_det = 1.0 / det;
    let s = origin - v0;
    let u = s.dot(p) * inv_det;
    if !(0.0..=1.0).contains(&u) {
        return None;
    }
    let q = s.cross(e1);
    let v = dir.dot(q) * inv_det;
    if !(v >= 0.0 && u + v <= 1.0) {
        return None;
    }
    let t = e2.dot(q) * inv_det;
    (t >= t_min && t <= t_max).then_some(t)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn both_sides_are_hit() {
        let tri = [Vec3::ZERO, Vec3::X, Vec3::Y];
        let o = Vec3::new(0.25, 0.25, 1.0);
        assert_eq!(intersect(o, -Vec3::Z, 0.0, f32::INFINITY, tri), Some(1.0));
        assert_eq!(intersect(-o, Vec3::Z, 0.0, f32::INFINITY, [Vec3::ZERO, -Vec3::X, -Vec3::Y]), Some(1.0));
        assert_eq!(intersect(o, -Vec3::Z, 0.0, 0.5, tri), None);
        assert_eq!(intersect(Vec3::new(0.75, 0.75, 1.0), -Vec3::Z, 0.0, f32::INFINITY, tri), None);
        assert_eq!(intersect(o, Vec3::X, 0.0, f32::INFINITY, tri), None);
    }
}
