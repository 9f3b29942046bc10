//! Building a [`Grid`]: its resolution, its limits, and its cells' lists.
//!
//! **Resolution.** Cleary and Wyvill (1988), "Analysis of an algorithm for fast ray tracing using
//! uniform space subdivision" (The Visual Computer), show that the cost of a grid traversal is
//! lowest when the number of cells grows linearly with the number of primitives, with cubic cells.
//! The grid has about `lambda^3 * N` cells: `lambda * N^(1/3)` along each axis of a cubic box, and
//! for any other box the same cell size along every axis (`s` cells per unit of length, with
//! `prod(extent * s) = lambda^3 * N`). An axis too thin for one cell at that density gets one cell
//! and the density is solved again over the others, so flat and thin scenes get square or linear
//! cells instead of a flood of them.
//!
//! **Limits.** A grid over a large scene can exhaust memory ("memory-hungry", the seed report
//! says): one big primitive overlaps many cells. The number of cells ([`GridParams::max_cells`])
//! and the number of references ([`GridParams::max_refs`], and at most
//! [`GridParams::max_refs_per_prim`] per primitive) are computed, not allocated, and the
//! density is lowered until both fit; at one cell the grid is brute force with a box.
//!
//! **Assignment.** A primitive is listed in every cell its box overlaps, boundaries included, with
//! the box grown by a small margin (`2^-18`, 32 units in the last place, of the largest coordinate of the grid's box): where a
//! ray crosses near an edge or a corner of cells, rounding may order its crossings wrongly by that
//! much, and a primitive touching that corner is then in whichever cell the traversal visits.
//! Each primitive's cells are found once, then counted and placed, in primitive order (so each
//! list is sorted).
//! Given a clipper (as the kd-tree is, see [`crate::shapes::clip_triangle`]), a primitive is left
//! out of the cells its box overlaps but its shape does not: a long thin triangle lying across the
//! diagonal of its box touches a few of the cells the box covers, and every cell it is wrongly
//! listed in costs the rays crossing that cell an exact test. The cell is grown by the same margin
//! before clipping.

use glam::DVec3;

use super::{Grid, GridParams};
use crate::Aabb;
use crate::accel::ClipFn;

/// Most cells along one axis.
pub const MAX_AXIS_CELLS: u32 = 1 << 12;

/// The margin of assignment, relative to the largest coordinate of the grid's box.
const MARGIN_SCALE: f32 = 1.0 / (1 << 18) as f32;

/// Cells along each axis for `n` primitives in `bounds` (see the module documentation); at least
/// one per axis, at most [`MAX_AXIS_CELLS`].
pub fn resolution(bounds: &Aabb, n: usize, lambda: f32) -> [u32; 3] {
    let e = bounds.extent().as_dvec3().max(DVec3::ZERO);
    let s = density(e, lambda as f64 * lambda as f64 * lambda as f64 * n as f64);
    at_density(e, s)
}

/// Cells per unit of length so that a box of extent `e` has about `target` cells.
fn density(e: DVec3, target: f64) -> f64 {
    if !(target >= 1.0) {
        return 0.0;
    }
    let mut active = [e.x > 0.0, e.y > 0.0, e.z > 0.0];
    loop {
        let dims = active.iter().filter(|&&a| a).count();
        if dims == 0 {
            return 0.0;
        }
        let measure: f64 = (0..3).filter(|&a| active[a]).map(|a| e[a]).product();
        let s = (target / measure).powf(1.0 / dims as f64);
        // The thinnest active axis with less than one cell gets one, and leaves the solve.
        let thin = (0..3).filter(|&a| active[a] && e[a] * s < 1.0).min_by(|&a, &b| e[a].total_cmp(&e[b]));
        match thin {
            Some(a) => active[a] = false,
            None => return s,
        }
    }
}

fn at_density(e: DVec3, s: f64) -> [u32; 3] {
    // NaN (an infinite density along an empty axis) and anything below one give one cell.
    let cells = |x: f64| {
        let v = x * s;
        if v >= 1.0 { v.round().min(MAX_AXIS_CELLS as f64) as u32 } else { 1 }
    };
    [cells(e.x), cells(e.y), cells(e.z)]
}

/// The grid's geometry, before any list exists: enough to assign boxes to cells.
struct Frame {
    bounds: Aabb,
    res: [u32; 3],
    inv_cell_size: glam::Vec3,
    margin: f32,
}

impl Frame {
    fn new(bounds: Aabb, res: [u32; 3], margin: f32) -> Self {
        let e = bounds.extent();
        let inv = |a: usize| if e[a] > 0.0 { res[a] as f32 / e[a] } else { 0.0 };
        Frame { bounds, res, inv_cell_size: glam::Vec3::new(inv(0), inv(1), inv(2)), margin }
    }

    /// The cells (inclusive ranges per axis) that box `b`, grown by the margin, overlaps.
    fn range(&self, b: &Aabb) -> [(u32, u32); 3] {
        let cell = |x: f32, a: usize| {
            let c = ((x - self.bounds.min[a]) * self.inv_cell_size[a]).floor();
            (c as i64).clamp(0, self.res[a] as i64 - 1) as u32
        };
        std::array::from_fn(|a| (cell(b.min[a] - self.margin, a), cell(b.max[a] + self.margin, a)))
    }

    fn cells(&self) -> u64 {
        self.res.iter().map(|&r| r as u64).product()
    }

    /// References all boxes would make, counted without allocating.
    fn count_refs(&self, boxes: &[Aabb]) -> u64 {
        boxes
            .iter()
            .filter(|b| has_box(b))
            .map(|b| self.range(b).iter().map(|&(lo, hi)| (hi - lo + 1) as u64).product::<u64>())
            .sum()
    }
}

fn has_box(b: &Aabb) -> bool {
    !b.is_empty() && b.is_finite()
}

pub(super) fn build(boxes: &[Aabb], clip: Option<ClipFn<'_>>, params: GridParams) -> Grid {
    let max_cells = params.max_cells.clamp(1, 1 << 30);
    let (bounds, n) = boxes.iter().filter(|b| has_box(b)).fold((Aabb::EMPTY, 0usize), |(u, n), b| (u.union(b), n + 1));
    let per_prim = params.max_refs_per_prim.max(1).saturating_mul(n as u64);
    let max_refs = params.max_refs.min(per_prim).clamp(1, u32::MAX as u64 - 1);
    if n == 0 {
        return Grid {
            bounds: Aabb::EMPTY,
            res: [0; 3],
            cell_size: glam::Vec3::ZERO,
            inv_cell_size: glam::Vec3::ZERO,
            cell_start: Vec::new(),
            refs: Vec::new(),
            margin: 0.0,
            prim_count: boxes.len(),
            mailbox: params.mailbox,
        };
    }
    let margin = bounds.min.abs().max(bounds.max.abs()).max_element() * MARGIN_SCALE;
    let e = bounds.extent().as_dvec3().max(DVec3::ZERO);
    let lambda = params.lambda as f64;
    // Beyond this density every axis is at its cap anyway; it keeps `s` finite.
    let mut s = density(e, lambda * lambda * lambda * n as f64).min(MAX_AXIS_CELLS as f64 / e.max_element());
    let frame = loop {
        let frame = Frame::new(bounds, at_density(e, s), margin);
        let cells = frame.cells();
        let single = cells == 1;
        if cells > max_cells {
            // Lower the density by the missing factor (spread over three axes at most), and a
            // little more so that rounding cannot keep it above the cap.
            s *= (max_cells as f64 / cells as f64).cbrt().min(0.95);
        } else if !single && frame.count_refs(boxes) > max_refs {
            s *= 0.8;
        } else {
            break frame;
        }
    };
    fill(boxes, clip, frame, params.mailbox)
}

/// Finds every primitive's cells, then counts and places them into the cells' lists.
fn fill(boxes: &[Aabb], clip: Option<ClipFn<'_>>, frame: Frame, mailbox: bool) -> Grid {
    let e = frame.bounds.extent();
    let size = |a: usize| if e[a] > 0.0 { e[a] / frame.res[a] as f32 } else { 0.0 };
    let mut grid = Grid {
        bounds: frame.bounds,
        res: frame.res,
        cell_size: glam::Vec3::new(size(0), size(1), size(2)),
        inv_cell_size: frame.inv_cell_size,
        cell_start: Vec::new(),
        refs: Vec::new(),
        margin: frame.margin,
        prim_count: boxes.len(),
        mailbox,
    };
    let margin = glam::Vec3::splat(frame.margin);
    // Every primitive's cells, in primitive order, with where each primitive's run ends: clipping
    // is the costly part of the build, so it is done once per primitive and cell.
    let (mut cells_of, mut ends) = (Vec::new(), Vec::new());
    for (prim, b) in boxes.iter().enumerate().filter(|(_, b)| has_box(b)) {
        let r = frame.range(b);
        let whole_box = r.iter().all(|&(lo, hi)| lo == hi);
        for z in r[2].0..=r[2].1 {
            for y in r[1].0..=r[1].1 {
                for x in r[0].0..=r[0].1 {
                    let touches = match clip {
                        Some(clip) if !whole_box => {
                            let cell = grid.cell_bounds(x, y, z);
                            !clip(prim as u32, &Aabb::new(cell.min - margin, cell.max + margin)).is_empty()
                        }
                        _ => true,
                    };
                    if touches {
                        cells_of.push(grid.linear(x, y, z) as u32);
                    }
                }
            }
        }
        ends.push((prim as u32, cells_of.len()));
    }
    let cells = frame.cells() as usize;
    let mut cell_start = vec![0u32; cells + 1];
    for &c in &cells_of {
        cell_start[c as usize + 1] += 1;
    }
    for c in 0..cells {
        cell_start[c + 1] += cell_start[c];
    }
    let mut refs = vec![0u32; cells_of.len()];
    let mut cursor = cell_start.clone();
    let mut from = 0;
    for &(prim, end) in &ends {
        for &c in &cells_of[from..end] {
            refs[cursor[c as usize] as usize] = prim;
            cursor[c as usize] += 1;
        }
        from = end;
    }
    grid.cell_start = cell_start;
    grid.refs = refs;
    grid
}

#[cfg(test)]
mod tests {
    use glam::Vec3;

    use super::*;

    fn cube(c: Vec3, r: f32) -> Aabb {
        Aabb::new(c - Vec3::splat(r), c + Vec3::splat(r))
    }

    #[test]
    fn a_cube_gets_lambda_times_the_cube_root_of_n_per_axis() {
        let b = Aabb::new(Vec3::ZERO, Vec3::splat(10.0));
        assert_eq!(resolution(&b, 1000, 2.0), [20, 20, 20]);
        assert_eq!(resolution(&b, 1000, 1.0), [10, 10, 10]);
        // A box twice as long: the same cells, twice as many along x.
        let long = Aabb::new(Vec3::ZERO, Vec3::new(20.0, 10.0, 10.0));
        let r = resolution(&long, 2000, 1.0);
        assert_eq!(r, [20, 10, 10]);
    }

    #[test]
    fn flat_and_thin_boxes_get_square_and_linear_cells() {
        let flat = Aabb::new(Vec3::ZERO, Vec3::new(10.0, 10.0, 0.0));
        assert_eq!(resolution(&flat, 100, 1.0), [10, 10, 1]);
        let thin = Aabb::new(Vec3::ZERO, Vec3::new(100.0, 0.01, 0.01));
        assert_eq!(resolution(&thin, 100, 1.0), [100, 1, 1]);
        let point = Aabb::new(Vec3::ONE, Vec3::ONE);
        assert_eq!(resolution(&point, 100, 2.0), [1, 1, 1]);
    }

    #[test]
    fn primitives_are_listed_in_every_cell_their_box_overlaps() {
        // 8 small cubes in the corners of a 4x4x4 box (2x2x2 cells at lambda 1), and one box
        // over everything.
        let mut boxes: Vec<Aabb> = (0..8)
            .map(|i| cube(Vec3::new((i & 1) as f32, ((i >> 1) & 1) as f32, (i >> 2) as f32) * 3.0 + 0.5, 0.5))
            .collect();
        boxes.push(Aabb::new(Vec3::ZERO, Vec3::splat(4.0)));
        let g = Grid::build_with(&boxes, GridParams { lambda: 8f32.cbrt() / 9f32.cbrt(), ..GridParams::default() });
        assert_eq!(g.resolution(), [2, 2, 2]);
        for i in 0..8u32 {
            let list = g.cell(i & 1, (i >> 1) & 1, i >> 2);
            assert_eq!(list, &[i, 8], "cell {i}");
        }
    }

    #[test]
    fn the_cell_cap_lowers_the_resolution_before_allocating() {
        let boxes: Vec<Aabb> = (0..1000).map(|i| cube(Vec3::new(i as f32, (i * 7 % 10) as f32, 0.0), 0.4)).collect();
        let g = Grid::build_with(&boxes, GridParams { max_cells: 500, ..GridParams::default() });
        assert!(g.cell_count() <= 500 && g.cell_count() > 100, "{:?}", g.resolution());
    }

    #[test]
    fn the_reference_cap_lowers_the_resolution_down_to_one_cell() {
        // Big overlapping boxes: every one of them overlaps most cells.
        let boxes: Vec<Aabb> = (0..200).map(|i| cube(Vec3::splat(i as f32 * 0.01), 10.0)).collect();
        let loose = Grid::build_with(&boxes, GridParams { max_refs_per_prim: u64::MAX, ..GridParams::default() });
        assert!(loose.refs.len() > 10_000);
        let capped = Grid::build_with(&boxes, GridParams { max_refs: 1000, ..GridParams::default() });
        assert!(capped.refs.len() <= 1000, "{}", capped.refs.len());
        let per_prim = Grid::build(&boxes);
        assert!(per_prim.refs.len() <= 64 * 200 && per_prim.cell_count() > 1, "{}", per_prim.refs.len());
        let tiny = Grid::build_with(&boxes, GridParams { max_refs: 10, ..GridParams::default() });
        assert_eq!((tiny.cell_count(), tiny.refs.len()), (1, 200), "one cell holds everything, whatever the cap");
    }

    #[test]
    fn absurd_parameters_are_clamped() {
        let boxes: Vec<Aabb> = (0..10).map(|i| cube(Vec3::splat(i as f32), 0.5)).collect();
        let g = Grid::build_with(&boxes, GridParams { lambda: 1e30, ..GridParams::default() });
        assert!(g.cell_count() as u64 <= GridParams::default().max_cells);
        let g = Grid::build_with(
            &boxes,
            GridParams { lambda: 0.0, max_cells: 0, max_refs: 0, max_refs_per_prim: 0, mailbox: true },
        );
        assert_eq!(g.cell_count(), 1);
        let g = Grid::build_with(&boxes, GridParams { lambda: f32::NAN, ..GridParams::default() });
        assert_eq!(g.cell_count(), 1);
    }

    #[test]
    fn nothing_to_build() {
        let g = Grid::build(&[Aabb::EMPTY, Aabb::new(Vec3::splat(f32::NAN), Vec3::ONE)]);
        assert_eq!(g.cell_count(), 0);
        assert!(g.bounds.is_empty());
    }

    #[test]
    fn a_clipper_keeps_a_diagonal_triangle_out_of_the_cells_it_misses() {
        // A thin triangle along the diagonal of the box, and small boxes filling the rest so that
        // the grid is fine: its box overlaps every cell, its shape only those near the diagonal.
        let tri = [Vec3::ZERO, Vec3::splat(8.0), Vec3::new(8.0, 8.0, 7.9)];
        let mut boxes = vec![Aabb::from_points(tri)];
        boxes.extend((0..511).map(|i| cube(Vec3::new((i % 8) as f32, (i / 8 % 8) as f32, (i / 64) as f32), 0.1)));
        let clip = |prim: u32, cell: &Aabb| {
            if prim == 0 { crate::shapes::clip_triangle(tri, cell) } else { boxes[prim as usize].intersection(cell) }
        };
        let params = GridParams { lambda: 1.0, ..GridParams::default() };
        let plain = Grid::build_with(&boxes, params);
        let clipped = Grid::build_with_clipper(&boxes, &clip, params);
        let listed = |g: &Grid| g.refs.iter().filter(|&&p| p == 0).count();
        let cells = plain.cell_count();
        assert_eq!(listed(&plain), cells);
        assert!(listed(&clipped) * 4 < cells, "{} of {cells} cells", listed(&clipped));
        // Every cell the triangle's diagonal crosses still lists it.
        let [nx, ny, nz] = clipped.resolution();
        for i in 0..nx.min(ny).min(nz) {
            assert!(clipped.cell(i, i, i).contains(&0), "cell {i}");
        }
        crate::accel::grid::stats::validate_grid_clipped(&clipped, &boxes, Some(&clip)).unwrap();
    }
}
