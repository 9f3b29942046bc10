//! The uniform grid: the box around the scene cut into equal cells, each cell listing every
//! primitive whose box overlaps it, traversed cell by cell along the ray.
//!
//! * [`build`]: the resolution (about `lambda * N^(1/3)` cells per axis of a cube, cells as close
//!   to cubes as the box's shape allows: Cleary and Wyvill 1988, "Analysis of an algorithm for fast
//!   ray tracing using uniform space subdivision", The Visual Computer), capped in cells and
//!   references before anything is allocated, and the cells' lists, filled by a counting sort.
//! * [`traverse`]: the 3D-DDA of Amanatides and Woo (1987), "A Fast Voxel Traversal Algorithm for
//!   Ray Tracing" (Eurographics), with mailboxing and the check that the closest hit lies in the
//!   current cell before stopping.
//! * [`stats`]: size, and the invariants of a built grid, checked.
//!
//! Layout: the cells' lists one after the other in one array of primitive indices, and for every
//! cell (x fastest, then y, then z) the offset of its list, plus one final offset: 4 bytes per cell
//! and 4 per reference.

pub mod build;
pub mod cells;
pub mod stats;
pub mod traverse;

pub use cells::{Grid, GridParams};

use glam::Vec3;

use super::{Accel, ClipFn, Counters, Hit, StructureStats};
use crate::PrimHit;
use crate::{Aabb, Ray};

impl Grid {
    /// Builds the grid over the primitives' boxes with the default parameters. Primitives with an
    /// empty or non-finite box are left out: no ray can be said to hit them.
    pub fn build(boxes: &[Aabb]) -> Self {
        build::build(boxes, None, GridParams::default())
    }

    /// Builds the grid with `params`.
    pub fn build_with(boxes: &[Aabb], params: GridParams) -> Self {
        build::build(boxes, None, params)
    }

    /// Builds the grid with `params`, listing a primitive only in the cells where
    /// `clip(prim, cell)` is not empty: the part of primitive `prim` inside `cell`, as for
    /// [`crate::accel::KdTree::build_with_clipper`].
    pub fn build_with_clipper(boxes: &[Aabb], clip: ClipFn<'_>, params: GridParams) -> Self {
        build::build(boxes, Some(clip), params)
    }

    /// Cells along each axis.
    pub fn resolution(&self) -> [u32; 3] {
        self.res
    }

    /// Number of cells.
    pub fn cell_count(&self) -> usize {
        self.cell_start.len().saturating_sub(1)
    }

    /// The primitives of cell `(x, y, z)`, in increasing order.
    #[inline(always)]
    pub fn cell(&self, x: u32, y: u32, z: u32) -> &[u32] {
        self.cell_by_index(self.linear(x, y, z))
    }

    #[inline(always)]
    fn linear(&self, x: u32, y: u32, z: u32) -> usize {
        (z as usize * self.res[1] as usize + y as usize) * self.res[0] as usize + x as usize
    }

    #[inline(always)]
    fn cell_by_index(&self, c: usize) -> &[u32] {
        &self.refs[self.cell_start[c] as usize..self.cell_start[c + 1] as usize]
    }

    /// The box of cell `(x, y, z)`, as the traversal sees its planes.
    pub fn cell_bounds(&self, x: u32, y: u32, z: u32) -> Aabb {
        let i = [x, y, z];
        let (mut min, mut max) = (Vec3::ZERO, Vec3::ZERO);
        for a in 0..3 {
            min[a] = self.plane(a, i[a] as i32);
            max[a] = if self.cell_size[a] > 0.0 { self.plane(a, i[a] as i32 + 1) } else { self.bounds.max[a] };
        }
        Aabb::new(min, max)
    }

    /// The position of the `i`-th cell boundary along `axis` (boundary 0 is the box's minimum).
    #[inline(always)]
    fn plane(&self, axis: usize, i: i32) -> f32 {
        self.bounds.min[axis] + i as f32 * self.cell_size[axis]
    }

    /// The cell holding coordinate `x` along `axis`, clamped to the grid.
    #[inline(always)]
    fn coord(&self, x: f32, axis: usize) -> i32 {
        let c = ((x - self.bounds.min[axis]) * self.inv_cell_size[axis]).floor();
        (c as i32).clamp(0, self.res[axis] as i32 - 1)
    }

    /// Number of primitives the grid was built over.
    pub fn prim_count(&self) -> usize {
        self.prim_count
    }

    /// The distance by which primitives' boxes were grown when they were assigned to cells.
    pub fn margin(&self) -> f32 {
        self.margin
    }
}

impl Accel for Grid {
    fn bounds(&self) -> Aabb {
        self.bounds
    }

    #[inline]
    fn closest_hit<C: Counters>(
        &self,
        ray: &Ray,
        counters: &mut C,
        intersect: impl FnMut(u32, &Ray) -> Option<PrimHit>,
    ) -> Option<Hit> {
        self.closest_hit_dda(ray, counters, intersect)
    }

    #[inline]
    fn any_hit<C: Counters>(&self, ray: &Ray, counters: &mut C, occludes: impl FnMut(u32, &Ray) -> bool) -> bool {
        self.any_hit_dda(ray, counters, occludes)
    }

    fn stats(&self) -> StructureStats {
        self.structure_stats()
    }
}
