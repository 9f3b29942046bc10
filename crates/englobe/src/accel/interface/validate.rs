//! One shape of validator for every structure: [`Validate::validate`] checks a built structure's
//! invariants against the boxes it was built over and returns its size and shape, or the broken
//! invariant. Each structure keeps its own detailed checker and error type (for instance
//! [`crate::accel::bvh::validate_bvh`]); this is the face they all show the test harness.

use super::clip::ClipFn;
use super::contract::StructureStats;
use crate::Aabb;

/// A structure that can check itself.
pub trait Validate {
    /// Checks every invariant of the structure built over `prim_boxes` (primitive `i` has box
    /// `prim_boxes[i]`). `clip` is the clipper it was built with, if any: a spatial subdivision
    /// need list a primitive only in the cells where the clipper finds part of it.
    fn validate(&self, prim_boxes: &[Aabb], clip: Option<ClipFn<'_>>) -> Result<StructureStats, InvalidStructure>;
}

/// A broken invariant, with the structure it was found in.
#[derive(Debug, thiserror::Error)]
#[error("invalid {structure}: {source}")]
pub struct InvalidStructure {
    /// What kind of structure it is.
    pub structure: &'static str,
    /// The structure's own description of what is wrong.
    pub source: Box<dyn std::error::Error + Send + Sync>,
}

impl InvalidStructure {
    /// The error `source` found in a structure of kind `structure`.
    pub fn new(structure: &'static str, source: impl std::error::Error + Send + Sync + 'static) -> Self {
        InvalidStructure { structure, source: Box::new(source) }
    }
}
