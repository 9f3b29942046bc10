//! The closest point of a [`TriangleBvh`]'s triangles to a query point, within a radius: what
//! Embree's `rtcPointQuery` and parry's `project_point` answer.
//!
//! A depth-first branch-and-bound walk, as Embree's point queries and parry's projections on a
//! BVH run it: the children entered nearest first, the search radius shrunk to the closest point
//! found so far. A child whose box is
//! farther than the closest point so far is never entered; one exactly as far is (of two
//! triangles at the same distance the lower index wins, as for rays).
//!
//! Each triangle's point is [`closest_point_on_triangle`] (Ericson 2005, section 5.1.5), whose
//! point lies inside the triangle's box: a box's [`distance_squared_to_box`] is then never more
//! than the distance to any triangle it holds, in `f32`, and pruning loses nothing. The answer is
//! the one testing every stored triangle in index order gives, bit for bit.

use glam::Vec3;

use super::TriangleBvh;
use super::node::{EMPTY, WIDTH, index_of, is_leaf};
use super::triangles::{LANES, UNUSED};
use crate::shapes::{closest_point_on_triangle, distance_squared, distance_squared_to_box};

/// The closest point of a mesh to a query point.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ClosestPoint {
    /// The triangle it lies on.
    pub prim: u32,
    /// The point.
    pub point: Vec3,
    /// Its distance to the query point.
    pub distance: f32,
}

/// Depth (in wide nodes) up to which the walk's stack lives on the call stack.
const INLINE_DEPTH: usize = 32;
const INLINE_ENTRIES: usize = (WIDTH - 1) * INLINE_DEPTH + 1;

/// A pending child: the squared distance to its box, its reference and its leaf item count.
type Entry = (f32, u32, u32);

impl TriangleBvh {
    /// The point of the stored triangles closest to `p` at a distance of at most `radius`
    /// (`f32::INFINITY` for no limit): the triangle, the point and the distance. Of two
    /// triangles at the same distance, the lower index wins. `None` if no triangle is that
    /// close, or if `p` is not finite or `radius` is negative or NaN.
    ///
    /// "Within the radius" means a squared distance of at most `radius * radius`, both in `f32`.
    ///
    /// ```
    /// use englobe::{TriangleBvh, Vec3};
    ///
    /// let bvh = TriangleBvh::from_triangles(&[[Vec3::ZERO, Vec3::X, Vec3::Y]]);
    /// let near = bvh.closest_point(Vec3::new(0.25, 0.25, 2.0), f32::INFINITY).expect("a point");
    /// assert_eq!((near.prim, near.point, near.distance), (0, Vec3::new(0.25, 0.25, 0.0), 2.0));
    /// assert!(bvh.closest_point(Vec3::new(0.25, 0.25, 2.0), 1.0).is_none());
    /// ```
    pub fn closest_point(&self, p: Vec3, radius: f32) -> Option<ClosestPoint> {
        if !p.is_finite() || !(radius >= 0.0) || self.nodes.is_empty() {
            return None;
        }
        let mut limit = radius * radius;
        let mut best: Option<(f32, u32, Vec3)> = None;
        let needed = (WIDTH - 1) * self.depth as usize + 1;
        let mut inline = [(0.0f32, 0u32, 0u32); INLINE_ENTRIES];
        let mut deep = Vec::new();
        let stack: &mut [Entry] = if needed <= INLINE_ENTRIES {
            &mut inline
        } else {
            deep.resize(needed, (0.0, 0, 0));
            &mut deep
        };
        stack[0] = (distance_squared_to_box(p, &self.bounds), 0, 0);
        let mut len = 1;
        while len > 0 {
            len -= 1;
            let (d2, reference, count) = stack[len];
            if d2 > limit {
                continue;
            }
            if is_leaf(reference) {
                let first = index_of(reference) as usize;
                for block in &self.blocks[first..first + count as usize] {
                    for lane in 0..LANES {
                        let prim = block.ids[lane];
                        if prim == UNUSED {
                            continue;
                        }
                        let q = closest_point_on_triangle(p, block.vertices(lane));
                        let d2 = distance_squared(p, q);
                        let better = match best {
                            None => d2 <= limit,
                            Some((b, b_prim, _)) => d2 < b || (d2 == b && prim < b_prim),
                        };
                        if better {
                            best = Some((d2, prim, q));
                            limit = d2;
                        }
                    }
                }
                continue;
            }
            let node = &self.nodes[reference as usize];
            let start = len;
            for slot in 0..WIDTH {
                let c = node.children[slot];
                if c == EMPTY {
                    continue;
                }
                let d2 = distance_squared_to_box(p, &node.child_bounds(slot));
                if d2 <= limit {
                    // Insertion in decreasing distance: the nearest child is popped first.
                    let mut i = len;
                    while i > start && stack[i - 1].0 < d2 {
                        stack[i] = stack[i - 1];
                        i -= 1;
                    }
                    stack[i] = (d2, c, node.counts[slot] as u32);
                    len += 1;
                }
            }
        }
        best.map(|(d2, prim, point)| ClosestPoint { prim, point, distance: d2.sqrt() })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_nearer_of_two_triangles_and_ties_to_the_lower_index() {
        let below = [Vec3::new(0.0, 0.0, -1.0), Vec3::new(1.0, 0.0, -1.0), Vec3::new(0.0, 1.0, -1.0)];
        let above = below.map(|v| v + Vec3::Z * 4.0);
        let bvh = TriangleBvh::from_triangles(&[above, below, above]);
        let p = Vec3::new(0.2, 0.2, 0.5);
        let near = bvh.closest_point(p, f32::INFINITY).unwrap();
        assert_eq!((near.prim, near.distance), (1, 1.5));
        let near = bvh.closest_point(Vec3::new(0.2, 0.2, 2.0), f32::INFINITY).unwrap();
        assert_eq!((near.prim, near.distance), (0, 1.0), "the first of two copies");
        assert!((near.point - Vec3::new(0.2, 0.2, 3.0)).length() < 1e-6, "{}", near.point);
        let midway = bvh.closest_point(Vec3::new(0.2, 0.2, 1.0), f32::INFINITY).unwrap();
        assert_eq!((midway.prim, midway.distance), (0, 2.0), "a tie between the two planes");
        assert_eq!(bvh.closest_point(p, 1.5).map(|c| c.prim), Some(1), "the radius is inclusive");
        assert_eq!(bvh.closest_point(p, 1.49), None);
        for (p, r) in [(Vec3::NAN, 1.0), (p, -1.0), (p, f32::NAN)] {
            assert_eq!(bvh.closest_point(p, r), None);
        }
        assert_eq!(TriangleBvh::from_triangles(&[]).closest_point(p, f32::INFINITY), None);
    }
}
