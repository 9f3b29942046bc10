//! Front-to-back traversal of a [`KdTree`] with early exit: the algorithm of pbrt-v3's
//! `KdTreeAccel::Intersect` (Pharr, Jakob and Humphreys, "Physically Based Rendering", 3rd ed.
//! 2016, section 4.4.4), which is Havran's recursive traversal TA^B_rec (Havran 2000, "Heuristic
//! Ray Shooting Algorithms", PhD thesis, Czech Technical University) in iterative form.
//!
//! The ray's interval inside the root cell is cut at each split plane into the part on the near
//! side and the part on the far side; the near child is entered first and the far one pushed with
//! its part. Leaves are thus reached in the order the ray crosses them, and a pending cell is
//! dropped once the closest hit so far lies before it: no later cell can hold a closer hit. Hits
//! found in a leaf may lie beyond it (a primitive straddles the plane); they stay in the query's
//! record, which is why no "hit inside the current cell" check is needed for correctness.
//!
//! Robustness at split planes:
//!
//! * A ray lying in a split plane (zero direction along the axis, origin on the plane) enters both
//!   children over its whole interval: primitives lying in the plane are in one of them, and
//!   primitives touching it from either side may be hit.
//! * The distance to a plane is computed with three roundings; both children's parts are widened
//!   by [`PLANE_SLACK`] of it around the plane, so that rounding never skips a cell the ray
//!   crosses near a plane, or near an edge where planes meet. Ties (a primitive in the next cell
//!   hit at exactly the closest distance) are visited: they may win by index.
//! * The near and far children follow from the sign of the direction alone, so a ray starting on
//!   a plane enters the side it comes from with an empty interval (and tests what touches the
//!   plane there) before the side it goes to.
//!
//! A primitive referenced by several leaves along the ray is tested once (see
//! [`crate::accel::interface::mailbox`]).

use std::ops::ControlFlow;

use super::{KdTree, MAX_DEPTH};
use crate::PrimHit;
use crate::Ray;
use crate::accel::interface::mailbox::Mailbox;
use crate::accel::{Counters, Hit, HitRecord};

/// Relative widening of the distances at which a ray crosses a split plane: eight units of
/// roundoff, more than the three roundings of `(split - origin) * inv_dir` and of the primitives'
/// own hit distances near the plane.
pub const PLANE_SLACK: f32 = 8.0 * f32::EPSILON;

/// A pending subtree: its node and the ray's interval in it.
type Pending = (u32, f32, f32);

impl KdTree {
    /// Calls `leaf` on the primitives of every leaf the ray's interval crosses, nearest first,
    /// skipping those that start beyond the limit `leaf` returns (the closest hit so far); `leaf`
    /// may stop the walk.
    #[inline(always)]
    fn walk<C: Counters>(
        &self,
        ray: &Ray,
        counters: &mut C,
        mut leaf: impl FnMut(&[u32], &mut C) -> ControlFlow<(), f32>,
    ) {
        if !ray.is_valid() || self.nodes.is_empty() {
            return;
        }
        counters.box_tests(1);
        let Some((enter, exit)) = self.bounds.intersect(ray) else { return };
        let (o, d, inv) = (ray.origin(), ray.dir(), ray.inv_dir());
        let mut limit = ray.t_max;
        let mut stack: [Pending; MAX_DEPTH as usize + 1] = [(0, 0.0, 0.0); MAX_DEPTH as usize + 1];
        let mut len = 0usize;
        // The slab test's entry distance is not widened: widen it here like a plane's.
        let (mut index, mut t_min, mut t_max) = (0usize, (enter - enter.abs() * PLANE_SLACK).max(ray.t_min), exit);
        loop {
            if t_min <= limit {
                let node = &self.nodes[index];
                counters.node_visited();
                if !node.is_leaf() {
                    let (axis, split) = (node.axis(), node.split());
                    let (below, above) = (index + 1, node.above_child());
                    if !inv[axis].is_finite() || d[axis] == 0.0 {
                        // Parallel to the plane: the side the ray runs on, or both if it runs in it.
                        if o[axis] < split {
                            index = below;
                        } else if o[axis] > split {
                            index = above;
                        } else {
                            stack[len] = (above as u32, t_min, t_max);
                            len += 1;
                            index = below;
                        }
                        continue;
                    }
                    let t_plane = (split - o[axis]) * inv[axis];
                    let slack = t_plane.abs() * PLANE_SLACK;
                    let (lo, hi) = (t_plane - slack, t_plane + slack);
                    let (near, far) = if d[axis] > 0.0 { (below, above) } else { (above, below) };
                    match (t_min <= hi, lo <= t_max) {
                        (true, true) => {
                            stack[len] = (far as u32, lo.max(t_min), t_max);
                            len += 1;
                            index = near;
                            t_max = hi.min(t_max);
                            continue;
                        }
                        (true, false) => {
                            index = near;
                            continue;
                        }
                        (false, true) => {
                            index = far;
                            continue;
                        }
                        // Only an empty interval gets here: nothing to visit.
                        (false, false) => {}
                    }
                } else {
                    match leaf(self.leaf_prims(node), counters) {
                        ControlFlow::Break(()) => return,
                        ControlFlow::Continue(l) => limit = l,
                    }
                }
            }
            if len == 0 {
                return;
            }
            len -= 1;
            let next = stack[len];
            (index, t_min, t_max) = (next.0 as usize, next.1, next.2);
        }
    }

    /// The closest hit (see [`crate::accel::Accel::closest_hit`]), leaves front to back.
    #[inline]
    pub fn closest_hit_front_to_back<C: Counters>(
        &self,
        ray: &Ray,
        counters: &mut C,
        mut intersect: impl FnMut(u32, &Ray) -> Option<PrimHit>,
    ) -> Option<Hit> {
        let mut record = HitRecord::new(*ray);
        let mut mailbox = Mailbox::new(self.mailbox);
        self.walk(ray, counters, |prims, counters| mailbox.closest_in(prims, &mut record, counters, &mut intersect));
        record.hit
    }

    /// Whether any primitive occludes the ray (see [`crate::accel::Accel::any_hit`]); stops at
    /// the first occluder.
    #[inline]
    pub fn any_hit_front_to_back<C: Counters>(
        &self,
        ray: &Ray,
        counters: &mut C,
        mut occludes: impl FnMut(u32, &Ray) -> bool,
    ) -> bool {
        let mut occluded = false;
        let mut mailbox = Mailbox::new(self.mailbox);
        self.walk(ray, counters, |prims, counters| {
            let flow = mailbox.any_in(prims, ray, counters, &mut occludes);
            occluded |= flow.is_break();
            flow
        });
        occluded
    }
}

#[cfg(test)]
mod tests {
    use glam::Vec3;

    use super::*;
    use crate::Aabb;
    use crate::accel::{KdTreeParams, WorkCounts};
    use crate::shapes::{Bounded, Intersect, Sphere};

    fn row(n: usize) -> Vec<Sphere> {
        (0..n).map(|i| Sphere::new(Vec3::new(0.0, 0.0, 2.0 + 3.0 * i as f32), 1.0)).collect()
    }

    fn boxes<T: Bounded>(shapes: &[T]) -> Vec<Aabb> {
        shapes.iter().map(Bounded::bounds).collect()
    }

    #[test]
    fn cells_behind_the_closest_hit_are_skipped() {
        let spheres = row(64);
        let tree = KdTree::build(&boxes(&spheres));
        let mut c = WorkCounts::default();
        let hit = tree
            .closest_hit_front_to_back(&Ray::new(Vec3::ZERO, Vec3::Z), &mut c, |i, r| spheres[i as usize].intersect(r));
        assert_eq!(hit.map(|h| (h.prim, h.t)), Some((0, 1.0)));
        assert!(c.exact_tests <= 2, "{c:?}");
        let back = Ray::new(Vec3::new(0.0, 0.0, 300.0), -Vec3::Z);
        let hit = tree.closest_hit_front_to_back(&back, &mut c, |i, r| spheres[i as usize].intersect(r));
        assert_eq!(hit.map(|h| h.prim), Some(63));
    }

    /// Boxes hit like solid boxes (a ray lying in a face hits it).
    fn hit_box(b: &[Aabb]) -> impl Fn(u32, &Ray) -> Option<PrimHit> + '_ {
        |p, r| b[p as usize].intersect(r).map(|(t, _)| PrimHit::at(t))
    }

    #[test]
    fn a_ray_in_a_split_plane_finds_what_touches_it_on_either_side() {
        // A below the plane x = 1 and B above it, both touching it, apart along y; two far boxes
        // make the tree split. Rays lie in the plane and run along y, both ways.
        let b = vec![
            Aabb::new(Vec3::new(0.0, 0.0, 0.0), Vec3::new(1.0, 1.0, 1.0)),
            Aabb::new(Vec3::new(1.0, 2.0, 0.0), Vec3::new(2.0, 3.0, 1.0)),
            Aabb::new(Vec3::new(-10.0, 0.0, 0.0), Vec3::new(-9.0, 3.0, 1.0)),
            Aabb::new(Vec3::new(11.0, 0.0, 0.0), Vec3::new(12.0, 3.0, 1.0)),
        ];
        let tree = KdTree::build(&b);
        assert!(tree.nodes().iter().any(|n| !n.is_leaf() && n.axis() == 0 && n.split() == 1.0), "{tree:?}");
        let mut c = WorkCounts::default();
        let up = Ray::new(Vec3::new(1.0, -5.0, 0.5), Vec3::Y);
        assert_eq!(tree.closest_hit_front_to_back(&up, &mut c, hit_box(&b)).map(|h| (h.prim, h.t)), Some((0, 5.0)));
        let down = Ray::new(Vec3::new(1.0, 8.0, 0.5), -Vec3::Y);
        assert_eq!(tree.closest_hit_front_to_back(&down, &mut c, hit_box(&b)).map(|h| (h.prim, h.t)), Some((1, 5.0)));
        // With -0 as the direction's zero component too.
        let down = Ray::new(Vec3::new(1.0, 8.0, 0.5), Vec3::new(-0.0, -1.0, 0.0));
        assert_eq!(tree.closest_hit_front_to_back(&down, &mut c, hit_box(&b)).map(|h| h.prim), Some(1));
    }

    #[test]
    fn a_ray_starting_on_a_plane_tests_what_touches_it_behind() {
        // A thin box on each side of x = 1 and a ray starting on the plane, going +x: the box
        // below the plane touches it at the origin and is hit at t = 0.
        let b = vec![
            Aabb::new(Vec3::new(0.0, 0.0, 0.0), Vec3::new(1.0, 1.0, 1.0)),
            Aabb::new(Vec3::new(1.0, 0.0, 0.0), Vec3::new(2.0, 1.0, 1.0)),
            Aabb::new(Vec3::new(-50.0, 0.0, 0.0), Vec3::new(-49.0, 1.0, 1.0)),
            Aabb::new(Vec3::new(50.0, 0.0, 0.0), Vec3::new(51.0, 1.0, 1.0)),
        ];
        let tree = KdTree::build(&b);
        let ray = Ray::new(Vec3::new(1.0, 0.5, 0.5), Vec3::X);
        let hit = tree.closest_hit_front_to_back(&ray, &mut WorkCounts::default(), hit_box(&b));
        assert_eq!(hit.map(|h| (h.prim, h.t)), Some((0, 0.0)));
    }

    #[test]
    fn a_primitive_across_many_leaves_is_tested_once() {
        // A long bar through a row of small boxes: the bar is in every leaf along the row.
        let mut b: Vec<Aabb> = (0..32)
            .map(|i| Aabb::new(Vec3::new(i as f32 * 2.0, 0.0, 0.0), Vec3::new(i as f32 * 2.0 + 1.0, 1.0, 1.0)))
            .collect();
        b.push(Aabb::new(Vec3::new(0.0, 0.0, 0.0), Vec3::new(64.0, 0.1, 0.1)));
        let bar = b.len() as u32 - 1;
        let ray = Ray::new(Vec3::new(-1.0, 0.05, 0.05), Vec3::X);
        let count = |mailbox: bool| {
            let params = KdTreeParams { mailbox, ..KdTreeParams::default() };
            let tree = KdTree::build_with_clipper(&b, &|p, c| b[p as usize].intersection(c), params);
            let mut tested = 0;
            // Nothing is hit, so every leaf along the ray is visited.
            tree.any_hit_front_to_back(&ray, &mut WorkCounts::default(), |p, _| {
                tested += (p == bar) as u32;
                false
            });
            tested
        };
        assert_eq!(count(true), 1);
        assert!(count(false) > 4, "the bar is referenced by many leaves");
    }

    #[test]
    fn invalid_rays_and_empty_trees_visit_nothing() {
        let spheres = row(3);
        let tree = KdTree::build(&boxes(&spheres));
        let mut c = WorkCounts::default();
        let bad = Ray::new(Vec3::ZERO, Vec3::ZERO);
        assert!(tree.closest_hit_front_to_back(&bad, &mut c, |_, _| Some(PrimHit::at(1.0))).is_none());
        assert!(!tree.any_hit_front_to_back(&bad, &mut c, |_, _| true));
        let empty = KdTree::build(&[]);
        assert!(!empty.any_hit_front_to_back(&Ray::new(Vec3::ZERO, Vec3::Z), &mut c, |_, _| true));
        assert_eq!(c, WorkCounts::default());
    }
}
