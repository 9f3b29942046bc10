//! Acceleration structures, all behind one interface.
//!
//! A structure is built from the primitives' bounding boxes alone and never sees their geometry:
//! a query takes a closure that tests primitive `i` exactly. So spheres, triangles, instances and
//! user shapes all work with every structure, and the work counters of [`counters`] measure every
//! structure the same way.
//!
//! * [`brute`]: no structure; the oracle every other one is checked against.
//! * [`bvh`]: the canonical binary BVH, its builders and traversals.
//! * [`kdtree`]: the SAH kd-tree, built in O(N log N) with split clipping.
//! * [`grid`]: the uniform grid, traversed with a 3D-DDA.
//! * [`mailbox`]: what spares the spatial subdivisions a second test of the same primitive.
//! * [`wide`]: the eight-wide BVH traversed with SIMD, and [`TriangleBvh`], its fast path for
//!   triangle meshes.
//! * [`validate`]: the invariants of a BVH, checked, and its quality, measured.

pub mod bound;
pub mod brute;
pub mod bvh;
pub mod counters;
pub mod grid;
pub mod kdtree;
pub mod mailbox;
pub mod validate;
pub mod wide;

use std::fmt;
use std::str::FromStr;

pub use bound::LowerBound;
pub use brute::BruteForce;
pub use bvh::{BinnedSah, Bvh, CandidateListBvh, Ploc, SeedPairing, SweepSah};
pub use counters::{Counters, NoCount, WorkCounts};
pub use grid::{Grid, GridParams};
pub use kdtree::{ClipFn, KdTree, KdTreeParams};
pub use wide::{Isa, TriangleBvh, WideBvh};

use crate::shapes::PrimHit;
use crate::{Aabb, Ray};

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
    /// [`bvh::stats`] for the constants).
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

/// The structures, by name: what `--accel` accepts.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum AccelKind {
    /// Brute force: no structure.
    None,
    /// The seed report's BVH ([`SeedPairing`]) with the report's traversal ([`CandidateListBvh`]).
    BvhSeed,
    /// The seed report's BVH with the ordered traversal of [`Bvh`].
    BvhSeedOrdered,
    /// A [`Bvh`] built top-down with the binned surface area heuristic ([`BinnedSah`]).
    BvhSah,
    /// A [`Bvh`] built bottom-up by parallel locally-ordered clustering ([`Ploc`]).
    BvhPloc,
    /// A [`Bvh`] built top-down with the full-sweep surface area heuristic ([`SweepSah`]).
    BvhSweep,
    /// Not a structure: the fewest exact tests any BVH over the same boxes could make
    /// ([`LowerBound`]), a yardstick for the others. Not in [`AccelKind::ALL`].
    Bound,
    /// The SAH kd-tree ([`KdTree`]).
    KdTree,
    /// The uniform grid ([`Grid`]).
    Grid,
    /// The fast path. Alone over boxes ([`AnyAccel`]), the binned SAH tree made eight-wide and
    /// traversed with SIMD, its leaves calling the exact test ([`WideBvh`]); in a
    /// [`crate::World`], two levels of it: every mesh a [`TriangleBvh`] (triangles in SIMD
    /// blocks) and a [`WideBvh`] over the objects on top.
    BvhWide,
}

impl AccelKind {
    /// Every structure, in the order tables list them.
    pub const ALL: &'static [AccelKind] = &[
        AccelKind::None,
        AccelKind::BvhSeed,
        AccelKind::BvhSeedOrdered,
        AccelKind::BvhSah,
        AccelKind::BvhPloc,
        AccelKind::BvhSweep,
        AccelKind::KdTree,
        AccelKind::Grid,
        AccelKind::BvhWide,
    ];

    /// Yardsticks that answer like brute force and count what the structures are measured
    /// against; named on the command line but not built by `compare` and the like.
    pub const REFERENCES: &'static [AccelKind] = &[AccelKind::Bound];

    /// The name used on the command line and in tables.
    pub fn name(self) -> &'static str {
        match self {
            AccelKind::None => "none",
            AccelKind::BvhSeed => "bvh-seed",
            AccelKind::BvhSeedOrdered => "bvh-seed-ordered",
            AccelKind::BvhSah => "bvh-sah",
            AccelKind::BvhPloc => "bvh-ploc",
            AccelKind::BvhSweep => "bvh-sweep",
            AccelKind::Bound => "bound",
            AccelKind::KdTree => "kdtree",
            AccelKind::Grid => "grid",
            AccelKind::BvhWide => "bvh-wide",
        }
    }

    /// One line saying what the structure is.
    pub fn description(self) -> &'static str {
        match self {
            AccelKind::None => "brute force: every ray tests every primitive",
            AccelKind::BvhSeed => {
                "the seed report's BVH and traversal: diagonal-key pairing, candidate list, every candidate tested"
            }
            AccelKind::BvhSeedOrdered => {
                "the seed report's BVH, traversed nearer child first with t_max shrinking at each hit"
            }
            AccelKind::BvhSah => "binary BVH built top-down with the binned surface area heuristic (32 bins per axis)",
            AccelKind::BvhPloc => {
                "binary BVH built bottom-up by parallel locally-ordered clustering, treelets restructured, leaves collapsed by the SAH"
            }
            AccelKind::BvhSweep => {
                "binary BVH built top-down with the full-sweep surface area heuristic (the quality reference)"
            }
            AccelKind::Bound => {
                "not a structure: the fewest exact tests any BVH over the primitives' boxes could make (answers by brute force)"
            }
            AccelKind::KdTree => {
                "SAH kd-tree built in O(N log N) with split clipping, traversed front to back with mailboxing"
            }
            AccelKind::Grid => "uniform grid of about 27 cells per primitive, traversed with the 3D-DDA and mailboxing",
            AccelKind::BvhWide => {
                "the fast path: eight-wide BVHs at both levels, meshes with triangles in SIMD blocks, children's boxes tested at once (AVX2, AVX-512 or portable)"
            }
        }
    }
}

impl fmt::Display for AccelKind {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

/// An unknown structure name.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("unknown accelerator `{given}`; expected one of: {}", AccelKind::ALL.iter().map(|k| k.name()).collect::<Vec<_>>().join(", "))]
pub struct UnknownAccel {
    /// The name that was given.
    pub given: String,
}

impl FromStr for AccelKind {
    type Err = UnknownAccel;
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        AccelKind::ALL
            .iter()
            .chain(AccelKind::REFERENCES)
            .copied()
            .find(|k| k.name() == s)
            .ok_or_else(|| UnknownAccel { given: s.to_owned() })
    }
}

/// Any structure, chosen at run time by [`AccelKind`]. Dispatch is one `match` per query, and
/// each arm is the structure's own fully inlined traversal.
#[derive(Clone, Debug)]
pub enum AnyAccel {
    /// See [`BruteForce`].
    BruteForce(BruteForce),
    /// See [`AccelKind::BvhSeed`].
    BvhSeed(CandidateListBvh),
    /// See [`AccelKind::BvhSeedOrdered`].
    BvhSeedOrdered(Bvh),
    /// See [`AccelKind::BvhSah`].
    BvhSah(Bvh),
    /// See [`AccelKind::BvhPloc`].
    BvhPloc(Bvh),
    /// See [`AccelKind::BvhSweep`].
    BvhSweep(Bvh),
    /// See [`AccelKind::Bound`].
    Bound(LowerBound),
    /// See [`AccelKind::KdTree`].
    KdTree(KdTree),
    /// See [`AccelKind::Grid`].
    Grid(Grid),
    /// See [`AccelKind::BvhWide`].
    BvhWide(WideBvh),
}

impl AnyAccel {
    /// Builds the structure `kind` over the primitives' boxes (at most [`MAX_PRIMITIVES`]).
    pub fn build(kind: AccelKind, boxes: &[Aabb]) -> Self {
        Self::build_with_clipper(kind, boxes, &|prim, cell| boxes[prim as usize].intersection(cell))
    }

    /// Builds the structure `kind`; structures that split primitives across cells (the kd-tree)
    /// ask `clip(prim, cell)` for the box of the part of primitive `prim` inside `cell`, which can
    /// be much tighter than the box's part (see [`crate::shapes::clip_triangle`]); the grid lists
    /// a primitive only in the cells where that part is not empty.
    pub fn build_with_clipper(kind: AccelKind, boxes: &[Aabb], clip: ClipFn<'_>) -> Self {
        match kind {
            AccelKind::KdTree => AnyAccel::KdTree(KdTree::build_with_clipper(boxes, clip, KdTreeParams::default())),
            AccelKind::Grid => AnyAccel::Grid(Grid::build_with_clipper(boxes, clip, GridParams::default())),
            AccelKind::None => AnyAccel::BruteForce(BruteForce::build(boxes)),
            AccelKind::BvhSeed => AnyAccel::BvhSeed(CandidateListBvh::build(boxes)),
            AccelKind::BvhSeedOrdered => AnyAccel::BvhSeedOrdered(SeedPairing::build(boxes)),
            AccelKind::BvhSah => AnyAccel::BvhSah(BinnedSah::default().build(boxes)),
            AccelKind::BvhPloc => AnyAccel::BvhPloc(Ploc::default().build(boxes)),
            AccelKind::BvhSweep => AnyAccel::BvhSweep(SweepSah::default().build(boxes)),
            AccelKind::Bound => AnyAccel::Bound(LowerBound::build(boxes)),
            AccelKind::BvhWide => AnyAccel::BvhWide(WideBvh::build(boxes)),
        }
    }

    /// The BVH behind the structure, if it is one (for validation and statistics).
    pub fn bvh(&self) -> Option<&Bvh> {
        match self {
            AnyAccel::BruteForce(_) | AnyAccel::Bound(_) | AnyAccel::BvhWide(_) => None,
            AnyAccel::BvhSeed(a) => Some(a.bvh()),
            AnyAccel::BvhSeedOrdered(a) | AnyAccel::BvhSah(a) | AnyAccel::BvhPloc(a) | AnyAccel::BvhSweep(a) => Some(a),
            AnyAccel::KdTree(_) | AnyAccel::Grid(_) => None,
        }
    }

    /// The kd-tree behind the structure, if it is one.
    pub fn kdtree(&self) -> Option<&KdTree> {
        if let AnyAccel::KdTree(t) = self { Some(t) } else { None }
    }

    /// The grid behind the structure, if it is one.
    pub fn grid(&self) -> Option<&Grid> {
        if let AnyAccel::Grid(g) = self { Some(g) } else { None }
    }
}

macro_rules! dispatch_accel {
    ($self:ident, $a:ident => $e:expr) => {
        match $self {
            AnyAccel::BruteForce($a) => $e,
            AnyAccel::BvhSeed($a) => $e,
            AnyAccel::BvhSeedOrdered($a) => $e,
            AnyAccel::BvhSah($a) => $e,
            AnyAccel::BvhPloc($a) => $e,
            AnyAccel::BvhSweep($a) => $e,
            AnyAccel::Bound($a) => $e,
            AnyAccel::KdTree($a) => $e,
            AnyAccel::Grid($a) => $e,
            AnyAccel::BvhWide($a) => $e,
        }
    };
}

impl Accel for AnyAccel {
    fn bounds(&self) -> Aabb {
        dispatch_accel!(self, a => a.bounds())
    }

    #[inline]
    fn closest_hit<C: Counters>(
        &self,
        ray: &Ray,
        counters: &mut C,
        intersect: impl FnMut(u32, &Ray) -> Option<PrimHit>,
    ) -> Option<Hit> {
        dispatch_accel!(self, a => a.closest_hit(ray, counters, intersect))
    }

    #[inline]
    fn any_hit<C: Counters>(&self, ray: &Ray, counters: &mut C, occludes: impl FnMut(u32, &Ray) -> bool) -> bool {
        dispatch_accel!(self, a => a.any_hit(ray, counters, occludes))
    }

    fn stats(&self) -> StructureStats {
        dispatch_accel!(self, a => a.stats())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_round_trip() {
        for &k in AccelKind::ALL.iter().chain(AccelKind::REFERENCES) {
            assert_eq!(k.name().parse::<AccelKind>().unwrap(), k);
        }
        let err = "octree".parse::<AccelKind>().unwrap_err();
        assert!(err.to_string().contains("none"), "{err}");
    }

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
