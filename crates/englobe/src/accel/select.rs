//! The registry: [`AccelKind`], the structures by name (what `--accel` accepts), and
//! [`AnyAccel`], a structure of any kind built at run time. The top floor of the accelerator
//! module: it imports every structure, and no structure imports it.

use std::fmt;
use std::str::FromStr;

use crate::accel::bvh::{BinnedSah, Bvh, Ploc, SweepSah};
use crate::accel::grid::{Grid, GridParams};
use crate::accel::kdtree::{KdTree, KdTreeParams};
use crate::accel::reference::{BruteForce, CandidateListBvh, LowerBound, SeedPairing};
use crate::accel::wide::WideBvh;
use crate::accel::{Accel, ClipFn, Counters, Hit, InvalidStructure, StructureStats, Validate};
#[cfg(doc)]
use crate::accel::{MAX_PRIMITIVES, TriangleBvh};
use crate::{Aabb, PrimHit, Ray};

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
            AccelKind::BvhSah => {
                "binary BVH built top-down with the binned surface area heuristic (up to 32 bins per axis)"
            }
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

impl Validate for AnyAccel {
    fn validate(&self, prim_boxes: &[Aabb], clip: Option<ClipFn<'_>>) -> Result<StructureStats, InvalidStructure> {
        dispatch_accel!(self, a => a.validate(prim_boxes, clip))
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
    fn no_structure_makes_fewer_exact_tests_than_the_lower_bound() {
        use crate::accel::WorkCounts;
        use crate::shapes::Intersect;
        use glam::Vec3;
        // A grazing ray entering several boxes.
        let (spheres, boxes) = crate::accel::reference::bound::spheres_along_z();
        let graze = Ray::new(Vec3::new(0.9, 0.9, -10.0), Vec3::new(0.0, 0.0, 1.0));
        let mut b = WorkCounts::default();
        let expected = LowerBound::build(&boxes).closest_hit(&graze, &mut b, |i, r| spheres[i as usize].intersect(r));
        assert!(b.exact_tests >= 3, "{b:?}");
        for kind in AccelKind::ALL.iter().copied().filter(|&k| k != AccelKind::None) {
            let accel = AnyAccel::build(kind, &boxes);
            let mut w = WorkCounts::default();
            let got = accel.closest_hit(&graze, &mut w, |i, r| spheres[i as usize].intersect(r));
            assert_eq!(got, expected, "{kind}");
            assert!(w.exact_tests >= b.exact_tests, "{kind}: {w:?} below the bound {b:?}");
        }
    }
}
