//! The builders of the canonical binary [`Bvh`](super::Bvh), each producing a
//! [`BuildTree`](super::BuildTree) that [`super::layout`] lays out:
//!
//! * [`binned_sah`]: top-down, binned surface area heuristic ([`BinnedSah`]).
//! * [`sweep_sah`]: top-down, every split candidate scored ([`SweepSah`]): the quality reference.
//! * [`ploc`]: bottom-up, parallel locally-ordered clustering ([`Ploc`]), with [`morton`] codes
//!   and the SAH leaf [`collapse`]; [`treelet`] restructuring improves its trees.
//! * [`top_down`]: what the top-down builders share; [`parallel`]: the builders' parallelism.
//!
//! The seed report's builder lives with the report's traversal in [`crate::accel::reference`].

pub mod binned_sah;
pub mod collapse;
pub mod morton;
pub mod parallel;
pub mod ploc;
pub mod sweep_sah;
pub mod top_down;
pub mod treelet;

pub use binned_sah::BinnedSah;
pub use ploc::Ploc;
pub use sweep_sah::SweepSah;
