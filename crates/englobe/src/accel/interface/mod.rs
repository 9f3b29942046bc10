//! The contract every acceleration structure implements, and what it is made of: [`Accel`]
//! (closest hit and any hit through a closure that tests primitive `i` exactly), the hit types
//! ([`Hit`], [`crate::PrimHit`]), the closest-hit record that gives every structure brute force's
//! tie rule ([`HitRecord`]), the work [`counters`], size and shape ([`StructureStats`]), the
//! clipping callback of spatial subdivisions ([`clip`]), the [`mailbox`] that spares them a
//! second test of a primitive, the one shape of validator ([`validate`]), and the runner of query
//! [`batch`]es, and the caller's hit [`filter`]s.
//!
//! This folder imports no structure: the structures import it.

pub mod batch;
pub mod clip;
pub mod contract;
pub mod counters;
pub mod filter;
pub mod mailbox;
pub mod validate;

pub use batch::{BatchSizeMismatch, PARALLEL_BATCH};
pub use clip::ClipFn;
pub use contract::{Accel, Hit, HitRecord, LEAF_SIZE_BUCKETS, MAX_PRIMITIVES, StructureStats};
pub use counters::{Counters, NoCount, WorkCounts};
pub use filter::{HitFilter, NoFilter};
pub use validate::{InvalidStructure, Validate};
