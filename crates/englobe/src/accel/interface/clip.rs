//! The clipping callback of the spatial subdivisions: what the kd-tree and the grid ask of a
//! primitive when they cut space into cells, so that a triangle is listed only where its shape
//! lies and not everywhere its box reaches (Havran 2000, "Heuristic Ray Shooting Algorithms",
//! section 4.5: split clipping). [`crate::shapes::clip_triangle`] answers it for triangles.

use crate::Aabb;

/// `clip(prim, cell)`: the box of the part of primitive `prim` inside `cell` (empty if none).
pub type ClipFn<'a> = &'a (dyn Fn(u32, &Aabb) -> Aabb + Sync);
