//! The fewest exact tests any bounding volume hierarchy over the primitives' boxes could make for
//! a ray: a yardstick for the seed experiment, not a structure to render with.
//!
//! In a BVH every node's box holds the boxes of the primitives below it, so a traversal must
//! enter the leaf of every primitive whose own box the ray enters before the closest hit (that
//! primitive could hold a closer hit until it is tested), and must test it. For an occlusion query
//! the best a structure can do is to test one occluder first. [`LowerBound`] finds the answer
//! without counting it (through an SAH BVH, which answers exactly as brute force does), then
//! counts exactly those tests: the primitives whose own box the ray enters before the closest hit,
//! or only one for an occluded ray. (Spatial subdivisions such as kd-trees clip primitives to
//! cells and can do better than this on some rays.)

use crate::PrimHit;
use crate::accel::bvh::{BinnedSah, Bvh};
use crate::accel::{Accel, ClipFn, Counters, Hit, InvalidStructure, NoCount, StructureStats, Validate};
use crate::{Aabb, Ray};

/// Answers like brute force but counts only the exact tests no BVH could avoid.
#[derive(Clone, Debug)]
pub struct LowerBound {
    boxes: Vec<Aabb>,
    bvh: Bvh,
}

impl LowerBound {
    /// The bound over these primitive boxes.
    pub fn build(boxes: &[Aabb]) -> Self {
        LowerBound { boxes: boxes.to_vec(), bvh: BinnedSah::default().build(boxes) }
    }

    /// Counts one exact test per primitive whose box `ray` enters within its interval.
    fn count_entered<C: Counters>(&self, ray: &Ray, counters: &mut C) {
        let mut entered = 0u64;
        // An occlusion query that never stops visits every leaf the ray enters, once.
        self.bvh.any_hit_ordered(ray, &mut NoCount, |prim, r| {
            entered += u64::from(self.boxes[prim as usize].intersect(r).is_some());
            false
        });
        for _ in 0..entered {
            counters.exact_test();
        }
    }
}

impl Accel for LowerBound {
    fn bounds(&self) -> Aabb {
        self.bvh.bounds()
    }

    fn closest_hit<C: Counters>(
        &self,
        ray: &Ray,
        counters: &mut C,
        intersect: impl FnMut(u32, &Ray) -> Option<PrimHit>,
    ) -> Option<Hit> {
        let hit = self.bvh.closest_hit(ray, &mut NoCount, intersect);
        if ray.is_valid() {
            self.count_entered(&ray.with_range(ray.t_min, hit.map_or(ray.t_max, |h| h.t)), counters);
        }
        hit
    }

    fn any_hit<C: Counters>(&self, ray: &Ray, counters: &mut C, occludes: impl FnMut(u32, &Ray) -> bool) -> bool {
        if self.bvh.any_hit(ray, &mut NoCount, occludes) {
            counters.exact_test();
            return true;
        }
        if ray.is_valid() {
            self.count_entered(ray, counters);
        }
        false
    }

    fn stats(&self) -> StructureStats {
        StructureStats {
            prim_refs: self.boxes.len(),
            memory_bytes: self.bvh.stats().memory_bytes + self.boxes.len() * std::mem::size_of::<Aabb>(),
            ..StructureStats::default()
        }
    }
}

impl Validate for LowerBound {
    /// The tree it finds the answers with, and the boxes it counts with.
    fn validate(&self, prim_boxes: &[Aabb], clip: Option<ClipFn<'_>>) -> Result<StructureStats, InvalidStructure> {
        if self.boxes != prim_boxes {
            let e = super::brute::CountMismatch { built: self.boxes.len(), given: prim_boxes.len() };
            return Err(InvalidStructure::new("lower bound", e));
        }
        self.bvh.validate(prim_boxes, clip)?;
        Ok(self.stats())
    }
}

/// Five spheres along +z, the third one's box reaching in front of the second's sphere, and their
/// boxes: the scene of the bound's tests and of the registry's test that no structure beats it.
#[cfg(test)]
pub(crate) fn spheres_along_z() -> (Vec<crate::Sphere>, Vec<Aabb>) {
    use crate::shapes::Bounded;
    let spheres: Vec<crate::Sphere> = [2.0, 5.0, 6.5, 20.0, 30.0]
        .iter()
        .enumerate()
        .map(|(i, &z)| crate::Sphere::new(glam::Vec3::new(if i == 0 { 5.0 } else { 0.0 }, 0.0, z), 1.0))
        .collect();
    let boxes = spheres.iter().map(Bounded::bounds).collect();
    (spheres, boxes)
}

#[cfg(test)]
mod tests {
    use glam::Vec3;

    use super::*;
    use crate::accel::WorkCounts;
    use crate::shapes::Intersect;

    #[test]
    fn counts_the_boxes_entered_before_the_hit() {
        let (spheres, boxes) = spheres_along_z();
        let bound = LowerBound::build(&boxes);
        let mut c = WorkCounts::default();
        let hit =
            bound.closest_hit(&Ray::new(Vec3::ZERO, Vec3::Z), &mut c, |i, r| spheres[i as usize].intersect(r)).unwrap();
        assert_eq!((hit.prim, hit.t), (1, 4.0));
        // Sphere 1 is hit at 4; sphere 2's box starts at 5.5: only the hit itself counts.
        assert_eq!(c.exact_tests, 1);
        let mut c = WorkCounts::default();
        assert!(
            bound.any_hit(&Ray::new(Vec3::ZERO, Vec3::Z), &mut c, |i, r| spheres[i as usize].intersect(r).is_some())
        );
        assert_eq!(c.exact_tests, 1);
        let mut c = WorkCounts::default();
        let miss = Ray::new(Vec3::new(5.0, 0.0, -1.0), -Vec3::Z);
        assert!(bound.closest_hit(&miss, &mut c, |i, r| spheres[i as usize].intersect(r)).is_none());
        assert_eq!(c.exact_tests, 0);
    }
}
