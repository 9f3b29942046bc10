//! The part of a triangle inside a box, as a box: what a kd-tree's split clipping needs so that a
//! triangle crossing a split plane is charged to each side only for the part it really has there.
//!
//! The triangle is clipped as a polygon against the six planes of the box, one plane after the
//! other, with the reentrant polygon clipping of Sutherland and Hodgman (1974), "Reentrant Polygon
//! Clipping" (CACM 17(1)); the bounds of what is left are the answer. This is the "perfect split"
//! clipping of Havran (2000), "Heuristic Ray Shooting Algorithms" (PhD thesis, Czech Technical
//! University), section 4.5, and of Wald and Havran (2006), "On building fast kd-trees for ray
//! tracing, and on doing that in O(N log N)".
//!
//! Clipping runs in `f64` and the result is rounded outward to `f32`, so the box returned always
//! holds the exact part of the triangle inside the box: a structure that relies on it never loses
//! a triangle to rounding. Boundaries count as inside: a triangle that only touches the box (along
//! an edge, at a vertex) gets the flat box of what touches.

use glam::{DVec3, Vec3};

use crate::Aabb;

/// Most vertices a triangle clipped by six planes can have: each plane adds at most one.
const MAX_VERTICES: usize = 3 + 6;

/// The bounds of the part of triangle `v` inside `cell` (boundaries included), rounded outward to
/// `f32` and never larger than `cell` or the triangle's own box; [`Aabb::EMPTY`] if the triangle
/// does not meet the cell.
pub fn clip_triangle(v: [Vec3; 3], cell: &Aabb) -> Aabb {
    let own = Aabb::from_points(v);
    let common = own.intersection(cell);
    if common.is_empty() {
        return Aabb::EMPTY;
    }
    if cell.contains_box(&own) {
        return own;
    }
    let mut poly = [DVec3::ZERO; MAX_VERTICES];
    let mut next = [DVec3::ZERO; MAX_VERTICES];
    for (p, q) in poly.iter_mut().zip(v) {
        *p = q.as_dvec3();
    }
    let mut len = 3;
    for axis in 0..3 {
        // Keep the side `x >= min` (sign 1), then the side `x <= max` (sign -1).
        for (plane, sign) in [(cell.min[axis] as f64, 1.0), (cell.max[axis] as f64, -1.0)] {
            len = clip_against(&poly[..len], &mut next, axis, plane, sign);
            if len == 0 {
                return Aabb::EMPTY;
            }
            std::mem::swap(&mut poly, &mut next);
        }
    }
    let (mut lo, mut hi) = (DVec3::splat(f64::INFINITY), DVec3::splat(f64::NEG_INFINITY));
    for p in &poly[..len] {
        lo = lo.min(*p);
        hi = hi.max(*p);
    }
    let rounded = Aabb::new(
        Vec3::new(round_down(lo.x), round_down(lo.y), round_down(lo.z)),
        Vec3::new(round_up(hi.x), round_up(hi.y), round_up(hi.z)),
    );
    // The polygon lies in the cell and in the triangle's box; rounding must not take it out.
    rounded.intersection(&common)
}

/// Room for a [`Polygon`]'s vertices: [`MAX_VERTICES`] and a margin for vertices that rounding
/// would leave doubled.
const POLYGON_ROOM: usize = 2 * MAX_VERTICES;

/// The part of a triangle inside a box, kept as a convex polygon (at most [`MAX_VERTICES`]
/// vertices: the triangle cut by at most six planes), so that it can be cut again by one plane
/// at a time: what cutting a triangle into pieces needs (see
/// [`crate::accel::wide::presplit`]).
#[derive(Clone, Copy, Debug)]
pub(crate) struct Polygon {
    vertices: [DVec3; POLYGON_ROOM],
    len: usize,
}

impl Polygon {
    /// The whole triangle.
    pub(crate) fn triangle(v: [Vec3; 3]) -> Self {
        let mut vertices = [DVec3::ZERO; POLYGON_ROOM];
        for (p, q) in vertices.iter_mut().zip(v) {
            *p = q.as_dvec3();
        }
        Polygon { vertices, len: 3 }
    }

    /// An empty polygon, to be filled by [`Polygon::split_into`].
    pub(crate) fn empty() -> Self {
        Polygon { vertices: [DVec3::ZERO; POLYGON_ROOM], len: 0 }
    }

    /// The parts of the polygon below and above the plane `x[axis] = plane` (boundaries
    /// included), written to `below` and `above`; a side may be empty. The polygon must lie
    /// inside a box whose planes include every plane it was cut by, which bounds its vertices.
    ///
    /// One pass over the edges for both sides: each side's vertices are those, and in the order,
    /// that [`clip_against`] gives it, and a crossing point both sides take is computed once.
    pub(crate) fn split_into(&self, axis: usize, plane: f64, below: &mut Polygon, above: &mut Polygon) {
        let poly = &self.vertices[..self.len];
        let (mut b, mut a) = (0, 0);
        let side = |p: &DVec3| {
            let d = p.as_ref()[axis] - plane;
            (d <= 0.0, d >= 0.0)
        };
        for (i, p) in poly.iter().enumerate() {
            let q = &poly[if i + 1 == poly.len() { 0 } else { i + 1 }];
            let ((p_below, p_above), (q_below, q_above)) = (side(p), side(q));
            // A convex polygon cut by a plane gains at most one vertex; each side has room.
            if p_below && b < POLYGON_ROOM {
                below.vertices[b] = *p;
                b += 1;
            }
            if p_above && a < POLYGON_ROOM {
                above.vertices[a] = *p;
                a += 1;
            }
            if p_below != q_below || p_above != q_above {
                let x = crossing(p, q, axis, plane);
                if p_below != q_below && b < POLYGON_ROOM {
                    below.vertices[b] = x;
                    b += 1;
                }
                if p_above != q_above && a < POLYGON_ROOM {
                    above.vertices[a] = x;
                    a += 1;
                }
            }
        }
        (below.len, above.len) = (b, a);
    }

    /// The polygon's bounds rounded outward to `f32` ([`Aabb::EMPTY`] if it is empty).
    pub(crate) fn bounds(&self) -> Aabb {
        let (mut lo, mut hi) = (DVec3::splat(f64::INFINITY), DVec3::splat(f64::NEG_INFINITY));
        for p in &self.vertices[..self.len] {
            lo = lo.min(*p);
            hi = hi.max(*p);
        }
        if self.len == 0 {
            return Aabb::EMPTY;
        }
        Aabb::new(
            Vec3::new(round_down(lo.x), round_down(lo.y), round_down(lo.z)),
            Vec3::new(round_up(hi.x), round_up(hi.y), round_up(hi.z)),
        )
    }
}

/// One step of Sutherland and Hodgman: the part of the closed polygon `poly` on the side
/// `sign * (x[axis] - plane) >= 0`, written to `out`; returns its number of vertices.
fn clip_against(poly: &[DVec3], out: &mut [DVec3], axis: usize, plane: f64, sign: f64) -> usize {
    let mut len = 0;
    let inside = |p: &DVec3| sign * (p.as_ref()[axis] - plane) >= 0.0;
    for (i, p) in poly.iter().enumerate() {
        let q = &poly[if i + 1 == poly.len() { 0 } else { i + 1 }];
        let (p_in, q_in) = (inside(p), inside(q));
        // A convex polygon cut by a plane gains at most one vertex; `out` has room for that.
        if p_in && len < out.len() {
            out[len] = *p;
            len += 1;
        }
        if p_in != q_in && len < out.len() {
            out[len] = crossing(p, q, axis, plane);
            len += 1;
        }
    }
    len
}

/// Where the edge from `p` to `q`, which crosses the plane `x[axis] = plane` (strictly, or from a
/// vertex on it), meets it: put exactly on the plane.
#[inline(always)]
fn crossing(p: &DVec3, q: &DVec3, axis: usize, plane: f64) -> DVec3 {
    let (pa, qa) = (p.as_ref()[axis], q.as_ref()[axis]);
    let s = (plane - pa) / (qa - pa);
    let mut x = *p + (*q - *p) * s;
    x.as_mut()[axis] = plane;
    x
}

/// The largest `f32` not above `x`.
fn round_down(x: f64) -> f32 {
    let f = x as f32;
    if (f as f64) > x { step_f32(f, false) } else { f }
}

/// The smallest `f32` not below `x`.
fn round_up(x: f64) -> f32 {
    let f = x as f32;
    if (f as f64) < x { step_f32(f, true) } else { f }
}

/// The next `f32` after the finite `f` towards +inf (`up`) or -inf.
fn step_f32(f: f32, up: bool) -> f32 {
    if f == 0.0 {
        let tiny = f32::from_bits(1);
        return if up { tiny } else { -tiny };
    }
    let bits = f.to_bits();
    let away_from_zero = (f > 0.0) == up;
    f32::from_bits(if away_from_zero { bits + 1 } else { bits - 1 })
}

#[cfg(test)]
mod tests {
    use rand::{RngExt, SeedableRng};
    use rand_pcg::Pcg32;

    use super::*;

    fn cube(min: f32, max: f32) -> Aabb {
        Aabb::new(Vec3::splat(min), Vec3::splat(max))
    }

    #[test]
    fn a_triangle_inside_keeps_its_box() {
        let v = [Vec3::ZERO, Vec3::X, Vec3::Y];
        assert_eq!(clip_triangle(v, &cube(-1.0, 2.0)), Aabb::from_points(v));
    }

    #[test]
    fn a_diagonal_triangle_is_clipped_tighter_than_its_box() {
        // The triangle (0,0,0) (4,0,0) (0,4,0) meets the cell [3,4]x[0,4]x[-1,1] only in its
        // corner near (4,0,0): x in [3,4], y in [0,1].
        let v = [Vec3::ZERO, Vec3::new(4.0, 0.0, 0.0), Vec3::new(0.0, 4.0, 0.0)];
        let cell = Aabb::new(Vec3::new(3.0, 0.0, -1.0), Vec3::new(4.0, 4.0, 1.0));
        let b = clip_triangle(v, &cell);
        assert_eq!(b, Aabb::new(Vec3::new(3.0, 0.0, 0.0), Vec3::new(4.0, 1.0, 0.0)));
        // The same triangle's box meets the cell [3,4]x[3,4]x[-1,1]; the triangle does not.
        let corner = Aabb::new(Vec3::new(3.0, 3.0, -1.0), Vec3::new(4.0, 4.0, 1.0));
        assert!(!Aabb::from_points(v).intersection(&corner).is_empty());
        assert!(clip_triangle(v, &corner).is_empty());
    }

    #[test]
    fn touching_counts_as_inside() {
        let v = [Vec3::ZERO, Vec3::new(2.0, 0.0, 0.0), Vec3::new(0.0, 2.0, 0.0)];
        // The cell starts on the hypotenuse's far vertex: only the point (2,0,0) is shared.
        let cell = Aabb::new(Vec3::new(2.0, -1.0, -1.0), Vec3::new(3.0, 1.0, 1.0));
        assert_eq!(clip_triangle(v, &cell), Aabb::new(Vec3::new(2.0, 0.0, 0.0), Vec3::new(2.0, 0.0, 0.0)));
        // A triangle in the plane z = 1 and a cell whose top face is that plane.
        let flat = [Vec3::new(0.0, 0.0, 1.0), Vec3::new(1.0, 0.0, 1.0), Vec3::new(0.0, 1.0, 1.0)];
        assert_eq!(clip_triangle(flat, &cube(0.0, 1.0)), Aabb::from_points(flat));
        assert!(clip_triangle(flat, &cube(-1.0, 0.5)).is_empty());
    }

    #[test]
    fn the_result_always_holds_sampled_points_of_the_triangle_in_the_cell() {
        // Awkward coordinates: the rounding outward must keep every point of the triangle that
        // lies in the cell.
        let mut rng = Pcg32::seed_from_u64(0x9e37_79b9);
        let mut next = move || rng.random::<f32>();
        for _ in 0..300 {
            let p = |n: &mut dyn FnMut() -> f32| Vec3::new(n() * 10.0 - 5.0, n() * 10.0 - 5.0, n() * 10.0 - 5.0);
            let v = [p(&mut next), p(&mut next), p(&mut next)];
            let (a, b) = (p(&mut next), p(&mut next));
            let cell = Aabb::new(a.min(b), a.max(b));
            let clipped = clip_triangle(v, &cell);
            assert!(cell.contains_box(&clipped) && Aabb::from_points(v).contains_box(&clipped));
            for i in 0..=40 {
                for j in 0..=(40 - i) {
                    let (u, w) = (i as f32 / 40.0, j as f32 / 40.0);
                    let x = v[0] + (v[1] - v[0]) * u + (v[2] - v[0]) * w;
                    if cell.contains_point(x) {
                        let slack = Aabb::new(clipped.min - Vec3::splat(1e-5), clipped.max + Vec3::splat(1e-5));
                        assert!(slack.contains_point(x), "{x} of {v:?} in {cell:?} but not in {clipped:?}");
                    }
                }
            }
        }
    }

    #[test]
    fn rounding_steps_outward() {
        let third = 1.0f64 / 3.0;
        assert!((round_down(third) as f64) <= third && (round_up(third) as f64) >= third);
        assert!(round_up(third) > round_down(third));
        assert_eq!(round_down(0.5), 0.5);
        assert_eq!(round_up(-0.5), -0.5);
        assert!(round_down(-1e-50) < 0.0 && round_up(1e-50) > 0.0);
        assert!(round_down(-third) <= -third as f32);
    }

    #[test]
    fn one_pass_split_gives_each_side_what_clipping_it_alone_gives() {
        // Triangles cut again and again, by planes through their vertices as often as not, so
        // that vertices on the plane (which both sides keep) and flat pieces occur.
        let mut rng = Pcg32::seed_from_u64(0x5b11_7000);
        let mut both_sides = 0;
        for _ in 0..5_000 {
            let mut p =
                || Vec3::new(rng.random_range(-4..=4) as f32, rng.random_range(-4..=4) as f32, rng.random::<f32>());
            let mut part = Polygon::triangle([p(), p(), p()]);
            for _ in 0..4 {
                let axis = rng.random_range(0..3);
                let plane = if rng.random() {
                    part.vertices[rng.random_range(0..part.len.max(1))].as_ref()[axis]
                } else {
                    rng.random_range(-4.0..4.0)
                };
                let (mut below, mut above) = (Polygon::empty(), Polygon::empty());
                part.split_into(axis, plane, &mut below, &mut above);
                for (side, sign) in [(&below, -1.0), (&above, 1.0)] {
                    let mut alone = [DVec3::ZERO; POLYGON_ROOM];
                    let len = clip_against(&part.vertices[..part.len], &mut alone, axis, plane, sign);
                    let bits = |v: &[DVec3]| v.iter().map(|p| p.to_array().map(f64::to_bits)).collect::<Vec<_>>();
                    assert_eq!(bits(&side.vertices[..side.len]), bits(&alone[..len]), "axis {axis} plane {plane}");
                }
                both_sides += (below.len > 0 && above.len > 0) as u32;
                part = if rng.random() && below.len > 0 { below } else { above };
                if part.len == 0 {
                    break;
                }
            }
        }
        assert!(both_sides > 5_000, "{both_sides}");
    }
}
