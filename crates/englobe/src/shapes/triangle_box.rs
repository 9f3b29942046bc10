//! Whether a triangle and a box overlap: the separating axis test of Akenine-Möller (2001),
//! "Fast 3D Triangle-Box Overlap Testing" (Journal of Graphics Tools 6(1)). Thirteen axes can
//! separate a triangle from a box: the box's three faces' normals, the triangle's normal and the
//! nine cross products of a triangle edge with a box axis. The two overlap if none does.
//!
//! The three box axes are tested first, on the coordinates as given, with comparisons alone
//! (exact): a triangle this test reports as overlapping always has a box that overlaps the query
//! box, so a structure may prune every node whose box misses the query box and still find every
//! triangle the test would. The other ten axes are tested about the box's centre, in `f32`;
//! boundaries count as overlapping (a triangle touching a face overlaps).

use glam::Vec3;

use crate::Aabb;

/// Whether triangle `v` overlaps `b` (boundaries included). False for an empty box.
pub fn triangle_overlaps_box(v: [Vec3; 3], b: &Aabb) -> bool {
    // The box's own axes: the triangle's box against it.
    let own = Aabb::from_points(v);
    if !(own.min.cmple(b.max).all() && b.min.cmple(own.max).all()) {
        return false;
    }
    let center = (b.min + b.max) * 0.5;
    let half = (b.max - b.min) * 0.5;
    let [v0, v1, v2] = v.map(|p| p - center);
    let edges = [v1 - v0, v2 - v1, v0 - v2];
    // The nine edge-by-axis cross products. For axis `e x u_k`, the radius of the box's
    // projection is `sum over the other two axes of half * |e component|`.
    for e in edges {
        for k in 0..3 {
            let axis = match k {
                0 => Vec3::new(0.0, -e.z, e.y),
                1 => Vec3::new(e.z, 0.0, -e.x),
                _ => Vec3::new(-e.y, e.x, 0.0),
            };
            if separates(axis, [v0, v1, v2], half) {
                return false;
            }
        }
    }
    // The triangle's plane.
    let normal = edges[0].cross(edges[1]);
    let radius = half.x * normal.x.abs() + half.y * normal.y.abs() + half.z * normal.z.abs();
    normal.dot(v0).abs() <= radius || !normal.is_finite()
}

/// Whether `axis` separates the triangle (vertices relative to the box's centre) from a box of
/// half-extents `half` about the origin.
#[inline(always)]
fn separates(axis: Vec3, v: [Vec3; 3], half: Vec3) -> bool {
    let p = v.map(|q| axis.dot(q));
    let (lo, hi) = (p[0].min(p[1]).min(p[2]), p[0].max(p[1]).max(p[2]));
    let radius = half.x * axis.x.abs() + half.y * axis.y.abs() + half.z * axis.z.abs();
    lo > radius || hi < -radius
}

#[cfg(test)]
mod tests {
    use rand::{RngExt, SeedableRng};
    use rand_pcg::Pcg32;

    use super::*;
    use crate::shapes::clip_triangle;

    #[test]
    fn inside_outside_and_across_the_corner() {
        let b = Aabb::new(Vec3::ZERO, Vec3::ONE);
        assert!(triangle_overlaps_box([Vec3::splat(0.2), Vec3::splat(0.3), Vec3::new(0.2, 0.8, 0.5)], &b));
        assert!(!triangle_overlaps_box([Vec3::splat(2.0), Vec3::splat(3.0), Vec3::new(2.0, 4.0, 2.0)], &b));
        // Larger than the box, through it.
        assert!(triangle_overlaps_box(
            [Vec3::new(-5.0, -5.0, 0.5), Vec3::new(5.0, -5.0, 0.5), Vec3::new(0.0, 5.0, 0.5)],
            &b
        ));
        // Its box overlaps the cube's, but it passes beyond the corner (x + y = 2.5 > 2).
        assert!(!triangle_overlaps_box(
            [Vec3::new(2.5, 0.0, -1.0), Vec3::new(0.0, 2.5, -1.0), Vec3::new(1.25, 1.25, 2.0)],
            &b
        ));
        // Its plane misses the cube though its box holds the cube (x + y + z = 3.5 > 3).
        let far = [Vec3::new(3.5, 0.0, 0.0), Vec3::new(0.0, 3.5, 0.0), Vec3::new(0.0, 0.0, 3.5)];
        assert!(!triangle_overlaps_box(far, &b));
        // Touching a face counts.
        assert!(triangle_overlaps_box(
            [Vec3::new(1.0, 0.2, 0.2), Vec3::new(2.0, 0.2, 0.2), Vec3::new(1.0, 0.8, 0.8)],
            &b
        ));
        assert!(!triangle_overlaps_box([Vec3::ZERO, Vec3::X, Vec3::Y], &Aabb::EMPTY));
    }

    /// Against the exact clipping of the triangle by the box (`f64` Sutherland-Hodgman): away
    /// from touching contacts, which the random cases never make, the two agree.
    #[test]
    fn agrees_with_clipping_on_random_triangles() {
        let mut rng = Pcg32::seed_from_u64(0x7b0c_5a71);
        let mut v = || Vec3::new(rng.random(), rng.random(), rng.random()) * 4.0 - 2.0;
        let (mut overlaps, mut misses) = (0, 0);
        for _ in 0..20_000 {
            let (c, e) = (v(), v().abs() * 0.5);
            let b = Aabb::new(c - e, c + e);
            let t = [v(), v(), v()];
            let expected = !clip_triangle(t, &b).is_empty();
            assert_eq!(triangle_overlaps_box(t, &b), expected, "{t:?} and {b:?}");
            if expected { overlaps += 1 } else { misses += 1 }
        }
        assert!(overlaps > 2000 && misses > 2000, "{overlaps} overlaps, {misses} misses");
    }
}
