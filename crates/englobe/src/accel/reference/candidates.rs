//! The seed report's own traversal: Deneux and Joniaux (2009), "Pré-détermination des objets
//! impactés par un rayon (accélération du rendu)", Université de Liège, sections 4.3 and 5.5.
//!
//! The tree is walked recursively from the root: a node whose box the ray misses is dropped with
//! its whole subtree; otherwise both children are visited, left then right, whatever the ray's
//! direction. The objects of the leaves reached form a list of candidates, and every candidate is
//! then tested exactly. Nothing found along the way shortens the walk: a box behind the closest
//! hit is still opened. That is what this structure measures.
//!
//! Candidates are gathered in a fixed buffer on the call stack rather than a list that grows, so
//! that a query allocates nothing; a full buffer is tested and emptied before the walk goes on.
//! Because the walk never looks at the tests' results, this tests exactly the same candidates as
//! one list tested at the end (and the tie rule of [`HitRecord`] makes the answer independent of
//! the order). Occlusion queries test candidates in the same order and stop at the first occluder.
//!
//! The recursion is as deep as the tree, and [`super::SeedPairing`] builds balanced
//! trees (`ceil(log2(n))` levels), so it stays within a few dozen frames.

use std::ops::ControlFlow;

use super::SeedPairing;
use crate::PrimHit;
use crate::accel::bvh::Bvh;
use crate::accel::{Accel, ClipFn, Counters, Hit, HitRecord, InvalidStructure, StructureStats, Validate};
use crate::{Aabb, Ray};

/// Candidates gathered before they are tested.
const BATCH: usize = 64;

/// The seed report's BVH with the report's traversal: recursive, candidate list, no ordering.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct CandidateListBvh {
    bvh: Bvh,
}

impl CandidateListBvh {
    /// Builds the report's tree ([`SeedPairing`]) over the primitives' boxes.
    pub fn build(boxes: &[Aabb]) -> Self {
        CandidateListBvh { bvh: SeedPairing::build(boxes) }
    }

    /// The tree.
    pub fn bvh(&self) -> &Bvh {
        &self.bvh
    }

    /// Visits the subtree of `index`, handing every primitive of every leaf reached to `found`.
    fn collect<C: Counters>(
        &self,
        index: usize,
        ray: &Ray,
        counters: &mut C,
        found: &mut impl FnMut(u32, &mut C) -> ControlFlow<()>,
    ) -> ControlFlow<()> {
        let node = &self.bvh.nodes()[index];
        counters.box_tests(1);
        if node.bounds().intersect(ray).is_none() {
            return ControlFlow::Continue(());
        }
        counters.node_visited();
        if node.is_leaf() {
            for &prim in &self.bvh.prim_indices()[node.prim_range()] {
                found(prim, counters)?;
            }
            ControlFlow::Continue(())
        } else {
            self.collect(index + 1, ray, counters, found)?;
            self.collect(node.index as usize, ray, counters, found)
        }
    }

    /// Walks the tree and calls `test` on batches of candidates; `test` may stop the walk.
    #[inline]
    fn for_candidates<C: Counters>(
        &self,
        ray: &Ray,
        counters: &mut C,
        mut test: impl FnMut(&[u32], &mut C) -> ControlFlow<()>,
    ) {
        if !ray.is_valid() || self.bvh.nodes().is_empty() {
            return;
        }
        let mut batch = [0u32; BATCH];
        let mut len = 0usize;
        let walk = self.collect(0, ray, counters, &mut |prim, counters| {
            batch[len] = prim;
            len += 1;
            if len == BATCH {
                len = 0;
                test(&batch, counters)
            } else {
                ControlFlow::Continue(())
            }
        });
        if walk.is_continue() && len > 0 {
            let _ = test(&batch[..len], counters);
        }
    }
}

impl Accel for CandidateListBvh {
    fn bounds(&self) -> Aabb {
        self.bvh.bounds()
    }

    fn closest_hit<C: Counters>(
        &self,
        ray: &Ray,
        counters: &mut C,
        mut intersect: impl FnMut(u32, &Ray) -> Option<PrimHit>,
    ) -> Option<Hit> {
        let mut record = HitRecord::new(*ray);
        // The walk uses the ray as given: the report's traversal never shortens it.
        self.for_candidates(ray, counters, |candidates, counters| {
            for &prim in candidates {
                counters.exact_test();
                if let Some(hit) = intersect(prim, &record.ray) {
                    record.offer(prim, hit);
                }
            }
            ControlFlow::Continue(())
        });
        record.hit
    }

    fn any_hit<C: Counters>(&self, ray: &Ray, counters: &mut C, mut occludes: impl FnMut(u32, &Ray) -> bool) -> bool {
        let mut occluded = false;
        self.for_candidates(ray, counters, |candidates, counters| {
            for &prim in candidates {
                counters.exact_test();
                if occludes(prim, ray) {
                    occluded = true;
                    return ControlFlow::Break(());
                }
            }
            ControlFlow::Continue(())
        });
        occluded
    }

    fn stats(&self) -> StructureStats {
        self.bvh.structure_stats()
    }
}

impl Validate for CandidateListBvh {
    fn validate(&self, prim_boxes: &[Aabb], clip: Option<ClipFn<'_>>) -> Result<StructureStats, InvalidStructure> {
        self.bvh().validate(prim_boxes, clip)
    }
}

#[cfg(test)]
mod tests {
    use glam::Vec3;

    use super::*;
    use crate::accel::WorkCounts;
    use crate::shapes::{Bounded, Intersect, Sphere};

    fn row(n: usize) -> Vec<Sphere> {
        (0..n).map(|i| Sphere::new(Vec3::new(0.0, 0.0, 2.0 + 3.0 * i as f32), 1.0)).collect()
    }

    #[test]
    fn every_candidate_on_the_ray_is_tested() {
        // 100 spheres on the ray, more than a batch: all are candidates, all are tested.
        let spheres = row(100);
        let boxes: Vec<Aabb> = spheres.iter().map(Bounded::bounds).collect();
        let accel = CandidateListBvh::build(&boxes);
        let mut c = WorkCounts::default();
        let hit = accel.closest_hit(&Ray::new(Vec3::ZERO, Vec3::Z), &mut c, |i, r| spheres[i as usize].intersect(r));
        assert_eq!(hit.map(|h| (h.prim, h.t)), Some((0, 1.0)));
        assert_eq!(c.exact_tests, 100);
        assert_eq!(c.nodes_visited, 199, "every node of the tree is opened");
        assert_eq!(c.box_tests, 199);
    }

    #[test]
    fn missed_boxes_prune_their_subtree() {
        let spheres = row(100);
        let boxes: Vec<Aabb> = spheres.iter().map(Bounded::bounds).collect();
        let accel = CandidateListBvh::build(&boxes);
        let mut c = WorkCounts::default();
        // Through the first sphere only, sideways.
        let ray = Ray::new(Vec3::new(-5.0, 0.0, 2.0), Vec3::X);
        let hit = accel.closest_hit(&ray, &mut c, |i, r| spheres[i as usize].intersect(r));
        assert_eq!(hit.map(|h| h.prim), Some(0));
        assert_eq!(c.exact_tests, 1);
        assert!(c.box_tests <= 2 * accel.bvh().depth() as u64 + 1, "{c:?}");
    }

    #[test]
    fn any_hit_stops_at_the_first_occluder_even_past_a_batch() {
        let spheres = row(100);
        let boxes: Vec<Aabb> = spheres.iter().map(Bounded::bounds).collect();
        let accel = CandidateListBvh::build(&boxes);
        let mut c = WorkCounts::default();
        // Only sphere 80 occludes: 81 candidates are tested (leaves come in key order).
        assert!(accel.any_hit(&Ray::new(Vec3::ZERO, Vec3::Z), &mut c, |i, _| i == 80));
        assert_eq!(c.exact_tests, 81);
        let mut c = WorkCounts::default();
        assert!(!accel.any_hit(&Ray::new(Vec3::ZERO, Vec3::Z), &mut c, |_, _| false));
        assert_eq!(c.exact_tests, 100);
    }
}
