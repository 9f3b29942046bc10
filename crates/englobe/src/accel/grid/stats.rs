//! Size of a [`Grid`], and its invariants, checked.
//!
//! A grid has no tree: in [`StructureStats`] its cells are its leaves (empty ones included), it
//! has no interior node, its depth is 0 and it has no SAH cost.
//!
//! [`validate_grid`] checks that the offsets are sorted and end at the number of references, that
//! every list is sorted and names existing primitives, that every primitive is listed in every
//! cell its box overlaps (completeness: the traversal relies on it; for a grid built with a
//! clipper, every such cell the clipper finds part of it in) and only in cells its box, grown by
//! the margin of assignment, overlaps (no stray references).

use super::Grid;
use crate::Aabb;
use crate::accel::{ClipFn, InvalidStructure, LEAF_SIZE_BUCKETS, StructureStats, Validate};

/// A broken invariant of a grid.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum GridError {
    /// The offsets are not a sorted list ending at the number of references.
    #[error("cell offsets are malformed: {0}")]
    Offsets(String),
    /// A cell's list is unsorted or names a primitive that does not exist.
    #[error("cell {cell}: {why}")]
    BadList {
        /// Linear cell index.
        cell: usize,
        /// What is wrong.
        why: String,
    },
    /// A primitive listed in a cell its box does not reach.
    #[error("cell {cell} lists primitive {prim}, whose box does not reach it")]
    StrayReference {
        /// Linear cell index.
        cell: usize,
        /// The primitive.
        prim: u32,
    },
    /// A primitive missing from a cell its box overlaps.
    #[error("primitive {prim} is missing from cell {cell}, which its box overlaps")]
    Missing {
        /// Linear cell index.
        cell: usize,
        /// The primitive.
        prim: usize,
    },
}

/// Shape of a valid grid.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GridQuality {
    /// Cells along each axis.
    pub resolution: [u32; 3],
    /// Cells.
    pub cells: usize,
    /// Cells with at least one primitive.
    pub non_empty_cells: usize,
    /// References in all lists.
    pub prim_refs: usize,
    /// References per primitive with a box.
    pub refs_per_prim: f64,
    /// Longest list.
    pub max_cell: usize,
}

impl Grid {
    /// Cells with at least one primitive.
    pub fn non_empty_cells(&self) -> usize {
        self.cell_start.windows(2).filter(|w| w[1] > w[0]).count()
    }

    /// Non-empty cells by number of primitives (see [`StructureStats::leaf_sizes`]); empty cells
    /// are not counted.
    pub fn leaf_sizes(&self) -> [usize; LEAF_SIZE_BUCKETS] {
        let mut sizes = [0; LEAF_SIZE_BUCKETS];
        for w in self.cell_start.windows(2) {
            let len = (w[1] - w[0]) as usize;
            if len > 0 {
                sizes[len.min(LEAF_SIZE_BUCKETS) - 1] += 1;
            }
        }
        sizes
    }

    /// References in all lists.
    pub fn prim_refs(&self) -> usize {
        self.refs.len()
    }

    /// Bytes held: the struct, the offsets and the lists.
    pub fn memory_bytes(&self) -> usize {
        std::mem::size_of::<Self>()
            + std::mem::size_of_val(self.cell_start.as_slice())
            + std::mem::size_of_val(self.refs.as_slice())
    }

    /// The statistics every structure reports: cells as leaves, no interior node, depth 0.
    pub fn structure_stats(&self) -> StructureStats {
        StructureStats {
            nodes: 0,
            leaves: self.cell_count(),
            depth: 0,
            prim_refs: self.refs.len(),
            memory_bytes: self.memory_bytes(),
            sah_cost: None,
            leaf_sizes: self.leaf_sizes(),
        }
    }
}

/// Checks every invariant of `grid` built over `prim_boxes`, and measures it.
pub fn validate_grid(grid: &Grid, prim_boxes: &[Aabb]) -> Result<GridQuality, GridError> {
    validate_grid_clipped(grid, prim_boxes, None)
}

/// [`validate_grid`] for a grid built with a clipper ([`Grid::build_with_clipper`]): a primitive
/// need only be listed in the cells its box overlaps where `clip` finds part of it.
pub fn validate_grid_clipped(
    grid: &Grid,
    prim_boxes: &[Aabb],
    clip: Option<ClipFn<'_>>,
) -> Result<GridQuality, GridError> {
    let has_box = |b: &Aabb| !b.is_empty() && b.is_finite();
    let with_box = prim_boxes.iter().filter(|b| has_box(b)).count();
    let cells = grid.cell_count();
    if grid.prim_count() != prim_boxes.len() || (cells == 0) != (with_box == 0) {
        return Err(GridError::Offsets(format!("{cells} cells for {with_box} primitives with a box")));
    }
    let expected_cells: usize = grid.res.iter().map(|&r| r as usize).product();
    if cells != 0 && cells != expected_cells {
        return Err(GridError::Offsets(format!("{cells} cells for a resolution of {:?}", grid.res)));
    }
    let starts = &grid.cell_start;
    if starts.first().is_some_and(|&s| s != 0)
        || starts.windows(2).any(|w| w[0] > w[1])
        || starts.last().is_some_and(|&s| s as usize != grid.refs.len())
    {
        return Err(GridError::Offsets("not sorted from 0 to the number of references".into()));
    }
    let [nx, ny, nz] = grid.res;
    let mut max_cell = 0;
    for z in 0..nz {
        for y in 0..ny {
            for x in 0..nx {
                let cell = grid.linear(x, y, z);
                let list = grid.cell_by_index(cell);
                max_cell = max_cell.max(list.len());
                if list.windows(2).any(|w| w[0] >= w[1]) {
                    return Err(GridError::BadList { cell, why: "not strictly increasing".into() });
                }
                let reach = grid.cell_bounds(x, y, z);
                let m = glam::Vec3::splat(grid.margin);
                for &prim in list {
                    let Some(b) = prim_boxes.get(prim as usize).filter(|b| has_box(b)) else {
                        return Err(GridError::BadList { cell, why: format!("primitive {prim} has no box") });
                    };
                    let grown = Aabb::new(b.min - m, b.max + m);
                    // Cell faces are rounded positions; allow one cell of rounding in the check.
                    let slack = Aabb::new(reach.min - grid.cell_size, reach.max + grid.cell_size);
                    if grown.intersection(&slack).is_empty() {
                        return Err(GridError::StrayReference { cell, prim });
                    }
                }
            }
        }
    }
    for (prim, b) in prim_boxes.iter().enumerate().filter(|(_, b)| has_box(b)) {
        let lo: [i32; 3] = std::array::from_fn(|a| grid.coord(b.min[a], a));
        let hi: [i32; 3] = std::array::from_fn(|a| grid.coord(b.max[a], a));
        for z in lo[2]..=hi[2] {
            for y in lo[1]..=hi[1] {
                for x in lo[0]..=hi[0] {
                    let (x, y, z) = (x as u32, y as u32, z as u32);
                    let cell = grid.linear(x, y, z);
                    let touches = clip.is_none_or(|clip| !clip(prim as u32, &grid.cell_bounds(x, y, z)).is_empty());
                    if touches && grid.cell_by_index(cell).binary_search(&(prim as u32)).is_err() {
                        return Err(GridError::Missing { cell, prim });
                    }
                }
            }
        }
    }
    Ok(GridQuality {
        resolution: grid.res,
        cells,
        non_empty_cells: grid.non_empty_cells(),
        prim_refs: grid.refs.len(),
        refs_per_prim: if with_box == 0 { 0.0 } else { grid.refs.len() as f64 / with_box as f64 },
        max_cell,
    })
}

impl Validate for Grid {
    fn validate(&self, prim_boxes: &[Aabb], clip: Option<ClipFn<'_>>) -> Result<StructureStats, InvalidStructure> {
        validate_grid_clipped(self, prim_boxes, clip).map_err(|e| InvalidStructure::new("grid", e))?;
        Ok(self.structure_stats())
    }
}

#[cfg(test)]
mod tests {
    use glam::Vec3;

    use super::*;

    fn scattered(n: usize) -> Vec<Aabb> {
        (0..n)
            .map(|i| {
                let c = Vec3::new((i * 7 % 13) as f32, (i * 5 % 11) as f32, (i * 3 % 7) as f32);
                Aabb::new(c, c + Vec3::splat(0.3 + (i % 4) as f32))
            })
            .collect()
    }

    #[test]
    fn built_grids_are_valid() {
        for n in [0, 1, 2, 9, 100, 700] {
            let boxes = scattered(n);
            let g = Grid::build(&boxes);
            let q = validate_grid(&g, &boxes).unwrap_or_else(|e| panic!("n = {n}: {e}"));
            let s = g.structure_stats();
            assert_eq!((s.nodes, s.leaves, s.depth, s.prim_refs), (0, q.cells, 0, q.prim_refs));
            assert_eq!(s.leaf_sizes.iter().sum::<usize>(), q.non_empty_cells);
            if n > 0 {
                assert!(q.refs_per_prim >= 1.0 && q.non_empty_cells > 0);
                assert_eq!(s.memory_bytes, std::mem::size_of::<Grid>() + 4 * (q.cells + 1) + 4 * q.prim_refs);
            }
        }
    }

    #[test]
    fn broken_grids_are_caught() {
        let boxes = scattered(100);
        let g = Grid::build(&boxes);
        let mut missing = g.clone();
        let c = missing.cell_start.windows(2).position(|w| w[1] > w[0]).unwrap();
        let at = missing.cell_start[c] as usize;
        missing.refs[at] = missing.refs[at].wrapping_add(1000);
        assert!(validate_grid(&missing, &boxes).is_err());
        let mut moved = boxes.clone();
        moved[5] = Aabb::new(Vec3::splat(-40.0), Vec3::splat(-39.0));
        assert!(validate_grid(&g, &moved).is_err());
        let mut offsets = g.clone();
        offsets.cell_start[1] = u32::MAX;
        assert!(matches!(validate_grid(&offsets, &boxes), Err(GridError::Offsets(_))));
    }
}
