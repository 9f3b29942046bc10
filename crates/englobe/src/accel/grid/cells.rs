//! The grid's data: its build parameters ([`GridParams`]) and the cells themselves ([`Grid`]),
//! apart from the code that builds, walks and checks them, which all reads these.

use glam::Vec3;

use crate::Aabb;

/// Build parameters. The defaults are those the measurements of `docs/accelerators.md` use.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GridParams {
    /// Cells per axis of a cubic box, per cube root of the number of primitives: a grid has about
    /// `lambda^3` cells per primitive. The default, 3, is pbrt's first edition's (Pharr and
    /// Humphreys 2004, "Physically Based Rendering", section 4.3); `docs/accelerators.md` measures
    /// others.
    pub lambda: f32,
    /// Most cells (the resolution is lowered until it fits). At most `2^30`.
    pub max_cells: u64,
    /// Most references in all cells' lists (the resolution is lowered until they fit, down to a
    /// single cell). At most `2^32 - 2`.
    pub max_refs: u64,
    /// Most references per primitive, on average (the resolution is lowered until they fit). A
    /// grid is worthless once primitives pile up on each other (100 000 copies of one triangle):
    /// this keeps its build and its memory linear in the primitives there.
    pub max_refs_per_prim: u64,
    /// Skip primitives a query has already tested in an earlier cell (see
    /// [`crate::accel::interface::mailbox`]); off only to measure what it saves.
    pub mailbox: bool,
}

impl Default for GridParams {
    fn default() -> Self {
        GridParams { lambda: 3.0, max_cells: 1 << 24, max_refs: 1 << 26, max_refs_per_prim: 64, mailbox: true }
    }
}

/// A uniform grid over primitives' boxes (see the module documentation).
#[derive(Clone, Debug, PartialEq)]
pub struct Grid {
    pub(super) bounds: Aabb,
    /// Cells along each axis (all 0 for an empty grid).
    pub(super) res: [u32; 3],
    /// Size of a cell along each axis (0 along an axis where the box is flat).
    pub(super) cell_size: Vec3,
    /// `res / extent` along each axis (0 where the box is flat: everything is in cell 0).
    pub(super) inv_cell_size: Vec3,
    /// Offset of every cell's list in `refs`, plus the end.
    pub(super) cell_start: Vec<u32>,
    pub(super) refs: Vec<u32>,
    /// Distance by which primitives' boxes are grown when cells are assigned (see [`super::build`]).
    pub(super) margin: f32,
    pub(super) prim_count: usize,
    pub(super) mailbox: bool,
}
