//! Acceleration structures, all behind one interface.
//!
//! A structure is built from the primitives' bounding boxes alone and never sees their geometry:
//! a query takes a closure that tests primitive `i` exactly. So spheres, triangles, instances and
//! user shapes all work with every structure, and the work counters measure every structure the
//! same way. The fast path adds one structure that also sees triangles ([`TriangleBvh`]).
//!
//! From the ground up (each folder imports only those above it in this list):
//!
//! * [`interface`]: the contract ([`Accel`], [`Hit`], [`HitRecord`], counters, [`StructureStats`],
//!   the clipping callback, the mailbox, the validator); it imports no structure.
//! * The field's structures: [`bvh`] (the canonical binary BVH, its layout, traversal, validator
//!   and, in [`bvh::build`], its builders), [`wide`] (the eight-wide SIMD BVH and the triangle
//!   BVH: the fast path), [`kdtree`] (the SAH kd-tree) and [`grid`] (the uniform grid with its
//!   3D-DDA).
//! * [`reference`](mod@reference): the seed report's own BVH and traversal, brute force (the oracle) and the
//!   lower bound (a yardstick), apart from the field's structures.
//! * [`select`]: the registry, [`AccelKind`] to a built structure; it imports every structure.

pub mod bvh;
pub mod grid;
pub mod interface;
pub mod kdtree;
pub mod reference;
pub mod select;
pub mod wide;

pub use bvh::{BinnedSah, Bvh, Ploc, SweepSah};
pub use grid::{Grid, GridParams};
pub use interface::{
    Accel, BatchSizeMismatch, ClipFn, Counters, Hit, HitFilter, HitRecord, InvalidStructure, LEAF_SIZE_BUCKETS,
    MAX_PRIMITIVES, NoCount, NoFilter, PARALLEL_BATCH, StructureStats, Validate, WorkCounts,
};
pub use kdtree::{KdTree, KdTreeParams};
pub use reference::{BruteForce, CandidateListBvh, LowerBound, SeedPairing};
pub use select::{AccelKind, AnyAccel, UnknownAccel};
pub use wide::{ClosestPoint, Isa, PacketHits, RayPacket, TriangleBvh, WideBvh};
