//! Brute force: every ray is tested against every primitive. It is the "before" of every
//! measurement and the oracle every other structure is checked against.

use crate::PrimHit;
use crate::accel::{Accel, ClipFn, Counters, Hit, HitRecord, InvalidStructure, StructureStats, Validate};
use crate::{Aabb, Ray};

/// Tests every primitive, in index order.
#[derive(Clone, Debug)]
pub struct BruteForce {
    count: u32,
    bounds: Aabb,
}

impl BruteForce {
    /// The "structure" over these primitive boxes (only their number and union are kept).
    pub fn build(boxes: &[Aabb]) -> Self {
        BruteForce { count: boxes.len() as u32, bounds: boxes.iter().fold(Aabb::EMPTY, |b, x| b.union(x)) }
    }
}

impl Accel for BruteForce {
    fn bounds(&self) -> Aabb {
        self.bounds
    }

    fn closest_hit<C: Counters>(
        &self,
        ray: &Ray,
        counters: &mut C,
        mut intersect: impl FnMut(u32, &Ray) -> Option<PrimHit>,
    ) -> Option<Hit> {
        if !ray.is_valid() {
            return None;
        }
        let mut record = HitRecord::new(*ray);
        for prim in 0..self.count {
            counters.exact_test();
            if let Some(hit) = intersect(prim, &record.ray) {
                record.offer(prim, hit);
            }
        }
        record.hit
    }

    fn any_hit<C: Counters>(&self, ray: &Ray, counters: &mut C, mut occludes: impl FnMut(u32, &Ray) -> bool) -> bool {
        if !ray.is_valid() {
            return false;
        }
        (0..self.count).any(|prim| {
            counters.exact_test();
            occludes(prim, ray)
        })
    }

    fn stats(&self) -> StructureStats {
        StructureStats {
            nodes: 0,
            leaves: 0,
            depth: 0,
            prim_refs: self.count as usize,
            memory_bytes: std::mem::size_of::<Self>(),
            sah_cost: None,
            leaf_sizes: [0; crate::accel::LEAF_SIZE_BUCKETS],
        }
    }
}
/// Brute force's one invariant: it tests every primitive.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
#[error("built over {built} primitives, checked against {given}")]
pub struct CountMismatch {
    /// Primitives it was built over.
    pub built: usize,
    /// Primitives it was checked against.
    pub given: usize,
}

impl Validate for BruteForce {
    fn validate(&self, prim_boxes: &[Aabb], _clip: Option<ClipFn<'_>>) -> Result<StructureStats, InvalidStructure> {
        if self.count as usize != prim_boxes.len() {
            let e = CountMismatch { built: self.count as usize, given: prim_boxes.len() };
            return Err(InvalidStructure::new("brute force", e));
        }
        Ok(self.stats())
    }
}
