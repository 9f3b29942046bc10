//! The point of a triangle closest to a query point: the Voronoi-region walk of Ericson (2005),
//! *Real-Time Collision Detection* (Morgan Kaufmann), section 5.1.5, "Closest Point on Triangle to
//! Point": the vertex regions first, then the edge regions, then the face, each decided by the
//! signs of a few dot products, with one division at most.
//!
//! Two additions make the answer something a structure can prune against exactly:
//!
//! * The point is clamped into the triangle's own box. Rounding may put Ericson's point a few ulps
//!   outside the triangle (and so outside every box that holds it); clamped, it lies inside, so
//!   [`distance_squared_to_box`] of any box holding the triangle is never more than the distance
//!   [`distance_squared`] measures to the point (the subtractions, squares and sums are monotonic,
//!   and both functions do them in the same order).
//! * A triangle so thin that the face case divides by zero (or overflows) gets the closest of its
//!   three edges' points instead.

use glam::Vec3;

use crate::Aabb;

/// `|p - q|^2`, summed x, then y, then z.
#[inline(always)]
pub fn distance_squared(p: Vec3, q: Vec3) -> f32 {
    let d = p - q;
    d.x * d.x + d.y * d.y + d.z * d.z
}

/// The squared distance from `p` to the closest point of `b` (0 inside), summed as
/// [`distance_squared`] sums, so that it never exceeds the distance to a point of the box.
/// Infinite for the empty box.
#[inline(always)]
pub fn distance_squared_to_box(p: Vec3, b: &Aabb) -> f32 {
    let gap = |axis: usize| {
        let (lo, hi, x) = (b.min[axis], b.max[axis], p[axis]);
        if x < lo {
            lo - x
        } else if x > hi {
            x - hi
        } else if lo <= hi {
            0.0
        } else {
            f32::INFINITY
        }
    };
    let (x, y, z) = (gap(0), gap(1), gap(2));
    x * x + y * y + z * z
}

/// The point of segment `a..b` closest to `p`.
#[inline]
fn closest_on_segment(p: Vec3, a: Vec3, b: Vec3) -> Vec3 {
    let ab = b - a;
    let len2 = ab.dot(ab);
    if !(len2 > 0.0) {
        return a;
    }
    let t = (p - a).dot(ab) / len2;
    if t <= 0.0 {
        a
    } else if t >= 1.0 {
        b
    } else {
        a + ab * t
    }
}

/// The point of triangle `a, b, c` closest to `p` (Ericson 2005, section 5.1.5), clamped into the
/// triangle's box (see the module documentation).
pub fn closest_point_on_triangle(p: Vec3, [a, b, c]: [Vec3; 3]) -> Vec3 {
    let q = ericson(p, a, b, c);
    let q = if q.is_finite() {
        q
    } else {
        // The face case of a (nearly) flat triangle: its boundary is the triangle.
        let candidates = [closest_on_segment(p, a, b), closest_on_segment(p, b, c), closest_on_segment(p, c, a)];
        let mut best = candidates[0];
        for q in &candidates[1..] {
            if distance_squared(p, *q) < distance_squared(p, best) {
                best = *q;
            }
        }
        best
    };
    let own = Aabb::from_points([a, b, c]);
    q.clamp(own.min, own.max)
}

/// Ericson's walk, as the book gives it.
#[inline]
fn ericson(p: Vec3, a: Vec3, b: Vec3, c: Vec3) -> Vec3 {
    let (ab, ac, ap) = (b - a, c - a, p - a);
    let (d1, d2) = (ab.dot(ap), ac.dot(ap));
    if d1 <= 0.0 && d2 <= 0.0 {
        return a;
    }
    let bp = p - b;
    let (d3, d4) = (ab.dot(bp), ac.dot(bp));
    if d3 >= 0.0 && d4 <= d3 {
        return b;
    }
    let vc = d1 * d4 - d3 * d2;
    if vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0 {
        return a + ab * (d1 / (d1 - d3));
    }
    let cp = p - c;
    let (d5, d6) = (ab.dot(cp), ac.dot(cp));
    if d6 >= 0.0 && d5 <= d6 {
        return c;
    }
    let vb = d5 * d2 - d1 * d6;
    if vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0 {
        return a + ac * (d2 / (d2 - d6));
    }
    let va = d3 * d6 - d5 * d4;
    if va <= 0.0 && d4 - d3 >= 0.0 && d5 - d6 >= 0.0 {
        return b + (c - b) * ((d4 - d3) / ((d4 - d3) + (d5 - d6)));
    }
    let denom = 1.0 / (va + vb + vc);
    a + ab * (vb * denom) + ac * (vc * denom)
}

#[cfg(test)]
mod tests {
    use rand::{RngExt, SeedableRng};
    use rand_pcg::Pcg32;

    use super::*;

    #[test]
    fn regions_of_a_right_triangle() {
        let t = [Vec3::ZERO, Vec3::X, Vec3::Y];
        let cases = [
            (Vec3::new(0.25, 0.25, 2.0), Vec3::new(0.25, 0.25, 0.0)),
            (Vec3::new(-1.0, -1.0, 0.5), Vec3::ZERO),
            (Vec3::new(2.0, -0.5, 0.0), Vec3::X),
            (Vec3::new(-0.5, 3.0, 0.0), Vec3::Y),
            (Vec3::new(0.5, -2.0, 1.0), Vec3::new(0.5, 0.0, 0.0)),
            (Vec3::new(-2.0, 0.5, -1.0), Vec3::new(0.0, 0.5, 0.0)),
            (Vec3::new(1.0, 1.0, 0.0), Vec3::new(0.5, 0.5, 0.0)),
        ];
        for (p, expected) in cases {
            assert_eq!(closest_point_on_triangle(p, t), expected, "{p}");
        }
    }

    /// Against a dense sampling of the triangle: the point found is never farther than the best
    /// sample (up to rounding), and it lies on the triangle.
    #[test]
    fn no_sample_of_the_triangle_is_closer() {
        let mut rng = Pcg32::seed_from_u64(0x5eed_c105);
        let mut v = || Vec3::new(rng.random(), rng.random(), rng.random()) * 4.0 - 2.0;
        for _ in 0..300 {
            let (t, p) = ([v(), v(), v()], v() * 2.0);
            let q = closest_point_on_triangle(p, t);
            let d = distance_squared(p, q).sqrt();
            let n = 60;
            for i in 0..=n {
                for j in 0..=n - i {
                    let (u, w) = (i as f32 / n as f32, j as f32 / n as f32);
                    let s = t[0] + (t[1] - t[0]) * u + (t[2] - t[0]) * w;
                    assert!(d <= p.distance(s) + 1e-4, "{p} to {t:?}: {q} at {d}, sample {s}");
                }
            }
            // On the triangle: its distance to the plane is zero and it is inside the box.
            let normal = (t[1] - t[0]).cross(t[2] - t[0]).normalize();
            assert!((q - t[0]).dot(normal).abs() < 1e-4, "{q} off the plane of {t:?}");
            assert!(Aabb::from_points(t).contains_point(q));
        }
    }

    #[test]
    fn flat_triangles_fall_back_to_their_edges() {
        let t = [Vec3::ZERO, Vec3::X, Vec3::X * 2.0];
        let q = closest_point_on_triangle(Vec3::new(1.5, 1.0, 0.0), t);
        assert!(q.is_finite());
        assert!((q - Vec3::new(1.5, 0.0, 0.0)).length() < 1e-6, "{q}");
    }

    #[test]
    fn the_box_distance_never_exceeds_a_point_distance() {
        let b = Aabb::new(Vec3::new(-1.0, 0.0, 2.0), Vec3::new(1.0, 0.5, 3.0));
        assert_eq!(distance_squared_to_box(Vec3::new(0.0, 0.25, 2.5), &b), 0.0);
        assert_eq!(distance_squared_to_box(Vec3::new(3.0, 0.25, 0.0), &b), 8.0);
        assert_eq!(distance_squared_to_box(Vec3::ZERO, &Aabb::EMPTY), f32::INFINITY);
    }
}
