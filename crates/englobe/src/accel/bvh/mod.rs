//! The canonical binary bounding volume hierarchy (BVH) that every BVH builder produces, and the
//! traversals that query it.
//!
//! The layout is the flat depth-first one of pbrt (Pharr, Jakob and Humphreys, "Physically Based
//! Rendering", 3rd ed. 2016, section 4.3.4, `LinearBVHNode`): 32-byte nodes in one array, the first
//! child of an interior node stored right after it, the node itself holding the index of its second
//! child; a leaf holds a range of `prim_indices`. The tree records its depth so that traversals can
//! size their stack once, without allocating per ray.
//!
//! * [`build`]: the builders (binned SAH, full sweep, PLOC with its Morton codes, treelets and
//!   leaf collapse), each producing a [`BuildTree`].
//! * [`layout`]: a builder's tree ([`BuildTree`]) laid out into a [`Bvh`].
//! * [`ordered`]: nearer child first, `t_max` shrinking at each hit (what `Bvh` answers queries
//!   with), over the [`slab`] test.
//! * [`stats`]: node count, leaves, depth, memory and SAH cost; [`validate`]: the invariants.
//!
//! The seed report's builder and traversal are in [`crate::accel::reference`].

pub mod build;
pub mod layout;
pub mod ordered;
pub mod slab;
pub mod stats;
pub mod tree;
pub mod validate;

pub use tree::{Bvh, BvhNode, INTERIOR, SECOND_IS_LOWER};

pub use build::{BinnedSah, Ploc, SweepSah};
pub use layout::{BuildKind, BuildNode, BuildTree};
pub use stats::{SAH_INTERSECTION_COST, SAH_TRAVERSAL_COST};
pub use validate::{BvhError, BvhQuality, validate_bvh};

use crate::PrimHit;
use crate::accel::{Accel, Counters, Hit, StructureStats};
use crate::{Aabb, Ray};

impl Accel for Bvh {
    fn bounds(&self) -> Aabb {
        Bvh::bounds(self)
    }

    #[inline]
    fn closest_hit<C: Counters>(
        &self,
        ray: &Ray,
        counters: &mut C,
        intersect: impl FnMut(u32, &Ray) -> Option<PrimHit>,
    ) -> Option<Hit> {
        self.closest_hit_ordered(ray, counters, intersect)
    }

    #[inline]
    fn any_hit<C: Counters>(&self, ray: &Ray, counters: &mut C, occludes: impl FnMut(u32, &Ray) -> bool) -> bool {
        self.any_hit_ordered(ray, counters, occludes)
    }

    fn stats(&self) -> StructureStats {
        self.structure_stats()
    }
}
