//! The contract itself: [`Accel`], the hit of a query ([`Hit`]), the closest-hit record that gives
//! every structure brute force's tie rule ([`HitRecord`]), size and shape ([`StructureStats`]) and
//! the limit on primitives ([`MAX_PRIMITIVES`]).

use super::counters::Counters;
use crate::{Aabb, PrimHit, Ray};

/// The closest hit of a query: the primitive's index and where it was hit.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Hit {
    /// Ray parameter of the hit.
    pub t: f32,
    /// Index of the primitive in the list the structure was built from.
    pub prim: u32,
    /// First surface coordinate (see [`PrimHit`]).
    pub u: f32,
    /// Second surface coordinate.
    pub v: f32,
}

/// The interface every acceleration structure implements.
///
/// Both queries honour the ray's `t_min..=t_max` and answer "no hit" for invalid rays
/// ([`Ray::is_valid`]) without visiting anything. The closure receives the ray with `t_max`
/// shrunk to the closest hit found so far, so it can reject farther hits early.
pub trait Accel: Send + Sync {
    /// The box around everything the structure holds.
    fn bounds(&self) -> Aabb;

    /// The closest primitive hit. Of two primitives hit at exactly the same `t`, the one with the
    /// lower index wins, so every structure gives the same answer as brute force.
    fn closest_hit<C: Counters>(
        &self,
        ray: &Ray,
        counters: &mut C,
        intersect: impl FnMut(u32, &Ray) -> Option<PrimHit>,
    ) -> Option<Hit>;

    /// Whether any primitive is hit; stops at the first one (shadow rays).
    fn any_hit<C: Counters>(&self, ray: &Ray, counters: &mut C, occludes: impl FnMut(u32, &Ray) -> bool) -> bool;

    /// Size and shape of the structure.
    fn stats(&self) -> StructureStats;
}

/// Size and shape of a built structure, for comparisons.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct StructureStats {
    /// Interior nodes (none for a grid).
    pub nodes: usize,
    /// Leaves, empty ones included (a grid's cells).
    pub leaves: usize,
    /// Longest path from the root to a leaf (0 when there is no tree).
    pub depth: usize,
    /// Primitive references stored in leaves (a primitive may be referenced more than once by
    /// spatial subdivisions).
    pub prim_refs: usize,
    /// Bytes used by the structure.
    pub memory_bytes: usize,
    /// Expected cost of a random ray under the surface area heuristic, where it applies (see
    /// [`crate::accel::bvh::stats`] for the constants).
    pub sah_cost: Option<f32>,
    /// Leaves by number of primitives: `leaf_sizes[k]` leaves hold `k + 1` primitives, for `k` up
    /// to [`LEAF_SIZE_BUCKETS`]` - 2`; the last entry counts all larger leaves. All zero where
    /// there are no leaves.
    pub leaf_sizes: [usize; LEAF_SIZE_BUCKETS],
}

/// Entries of [`StructureStats::leaf_sizes`]: leaves of 1 to 8 primitives, then larger ones.
pub const LEAF_SIZE_BUCKETS: usize = 9;

/// The closest hit found so far during a query, and the ray shrunk to it. Every structure offers
/// its candidates through this, so they all break ties the same way.
#[derive(Clone, Copy, Debug)]
pub struct HitRecord {
    /// The query ray with `t_max` shrunk to the closest hit so far.
    pub ray: Ray,
    /// The closest hit so far.
    pub hit: Option<Hit>,
}

impl HitRecord {
    /// No hit yet.
    #[inline(always)]
    pub fn new(ray: Ray) -> Self {
        HitRecord { ray, hit: None }
    }

    /// Keeps `hit` on `prim` if it is closer than the current one, or as close with a lower
    /// index. Returns true if it was kept.
    #[inline(always)]
    pub fn offer(&mut self, prim: u32, hit: PrimHit) -> bool {
        let better = match self.hit {
            None => true,
            Some(best) => hit.t < best.t || (hit.t == best.t && prim < best.prim),
        };
        if better {
            self.hit = Some(Hit { t: hit.t, prim, u: hit.u, v: hit.v });
            self.ray.t_max = hit.t;
        }
        better
    }
}

/// Most primitives a structure can be built over: node indices are 32-bit, and a binary tree over
/// `n` primitives has up to `2n - 1` nodes.
pub const MAX_PRIMITIVES: usize = (1 << 31) - 1;

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ties_go_to_the_lower_index() {
        let mut r = HitRecord::new(Ray::new(glam::Vec3::ZERO, glam::Vec3::X));
        assert!(r.offer(5, PrimHit::at(2.0)));
        assert!(r.offer(3, PrimHit::at(2.0)));
        assert!(!r.offer(4, PrimHit::at(2.0)));
        assert!(!r.offer(0, PrimHit::at(2.5)));
        assert_eq!(r.hit.unwrap().prim, 3);
        assert_eq!(r.ray.t_max, 2.0);
    }
}
