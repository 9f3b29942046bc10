//! The 3D-DDA of Amanatides and Woo (1987), "A Fast Voxel Traversal Algorithm for Ray Tracing"
//! (Eurographics): from the cell where the ray enters the grid, step to the neighbour across
//! whichever cell face the ray reaches first, so that the cells are visited in the order the ray
//! crosses them.
//!
//! * **Closest hit.** A primitive listed in the current cell may be hit beyond the cell (it
//!   straddles into the next ones). Amanatides and Woo stop only when the closest hit lies inside
//!   the current cell: any cell further on starts after it. The hit found earlier is kept in the
//!   query's record, not thrown away, so nothing needs testing again, and the walk goes on while
//!   the closest hit is at or beyond the cell's exit: a primitive in the next cell hit at exactly
//!   that distance may win the tie by its lower index.
//! * **Mailboxing.** A primitive listed in several cells along the ray is tested once (see
//!   [`crate::accel::interface::mailbox`]).
//! * **Robustness.** The distances to the next faces are computed afresh from each face's position
//!   (not accumulated, which would drift), and the start cell is found from the entry point moved
//!   back along the ray by its rounding error, so the walk never starts past the cell the ray
//!   really enters (it may start one cell early, visited for nothing). Crossings that rounding
//!   orders wrongly near an edge or corner are covered by the margin of assignment (see
//!   [`super::build`]). A ray parallel to an axis keeps its cell along that axis; a ray lying in a
//!   cell face stays on one side of it, which the margin makes equivalent to the other.
//!
//! Rays that start outside the grid enter it through the box's slab test; rays that start inside,
//! or on its boundary, start in their own cell.

use std::ops::ControlFlow;

use super::Grid;
use crate::PrimHit;
use crate::Ray;
use crate::accel::interface::mailbox::Mailbox;
use crate::accel::{Counters, Hit, HitRecord};
use crate::geom::aabb::gamma;

/// Relative slack on a cell's exit distance when deciding that the closest hit lies inside it.
pub const EXIT_SLACK: f32 = 8.0 * f32::EPSILON;

impl Grid {
    /// Calls `cell` on the primitives of every cell the ray's interval crosses, in order, until
    /// the limit `cell` returns (the closest hit so far) lies before the current cell's exit;
    /// `cell` may stop the walk.
    #[inline(always)]
    fn walk<C: Counters>(
        &self,
        ray: &Ray,
        counters: &mut C,
        mut cell: impl FnMut(&[u32], &mut C) -> ControlFlow<(), f32>,
    ) {
        if !ray.is_valid() || self.cell_start.is_empty() {
            return;
        }
        counters.box_tests(1);
        let Some((enter, _)) = self.bounds.intersect(ray) else { return };
        let (o, d, inv) = (ray.origin(), ray.dir(), ray.inv_dir());
        let entry = ray.at(enter);
        let mut index = [0i32; 3];
        let mut step = [0i32; 3];
        let mut t_next = [f32::INFINITY; 3];
        for a in 0..3 {
            let moving = d[a] != 0.0 && inv[a].is_finite();
            // The entry point is off by a few roundings of `o + t * d`: start from a point that
            // far back along the ray, never past the true cell.
            let back = if moving { gamma(4) * (o[a].abs() + (enter * d[a]).abs()) + self.margin } else { 0.0 };
            let x = if d[a] > 0.0 { entry[a] - back } else { entry[a] + back };
            index[a] = self.coord(if moving { x } else { o[a] }, a);
            if moving {
                step[a] = if d[a] > 0.0 { 1 } else { -1 };
                t_next[a] = self.face_distance(ray, a, index[a], step[a]);
            }
        }
        let mut linear = self.linear(index[0] as u32, index[1] as u32, index[2] as u32);
        let stride = [1isize, self.res[0] as isize, self.res[0] as isize * self.res[1] as isize];
        loop {
            counters.node_visited();
            let t_exit = t_next[0].min(t_next[1]).min(t_next[2]);
            match cell(self.cell_by_index(linear), counters) {
                ControlFlow::Break(()) => return,
                ControlFlow::Continue(limit) => {
                    if limit < t_exit - t_exit.abs() * EXIT_SLACK {
                        return;
                    }
                }
            }
            // Across the nearest face; equal distances step x, then y, then z, visiting the cells
            // between (each for no length of the ray).
            let a = if t_next[0] <= t_next[1] && t_next[0] <= t_next[2] {
                0
            } else if t_next[1] <= t_next[2] {
                1
            } else {
                2
            };
            if step[a] == 0 {
                return;
            }
            index[a] += step[a];
            if index[a] < 0 || index[a] >= self.res[a] as i32 {
                return;
            }
            linear = (linear as isize + step[a] as isize * stride[a]) as usize;
            t_next[a] = self.face_distance(ray, a, index[a], step[a]);
        }
    }

    /// Distance along the ray to the face of cell `i` (along `axis`) it leaves through, going in
    /// direction `step`.
    #[inline(always)]
    fn face_distance(&self, ray: &Ray, axis: usize, i: i32, step: i32) -> f32 {
        let face = self.plane(axis, if step > 0 { i + 1 } else { i });
        (face - ray.origin()[axis]) * ray.inv_dir()[axis]
    }

    /// The closest hit (see [`crate::accel::Accel::closest_hit`]), cell by cell.
    #[inline]
    pub fn closest_hit_dda<C: Counters>(
        &self,
        ray: &Ray,
        counters: &mut C,
        mut intersect: impl FnMut(u32, &Ray) -> Option<PrimHit>,
    ) -> Option<Hit> {
        let mut record = HitRecord::new(*ray);
        let mut mailbox = Mailbox::new(self.mailbox);
        self.walk(ray, counters, |prims, counters| mailbox.closest_in(prims, &mut record, counters, &mut intersect));
        record.hit
    }

    /// Whether any primitive occludes the ray (see [`crate::accel::Accel::any_hit`]); stops at
    /// the first occluder.
    #[inline]
    pub fn any_hit_dda<C: Counters>(
        &self,
        ray: &Ray,
        counters: &mut C,
        mut occludes: impl FnMut(u32, &Ray) -> bool,
    ) -> bool {
        let mut occluded = false;
        let mut mailbox = Mailbox::new(self.mailbox);
        self.walk(ray, counters, |prims, counters| {
            let flow = mailbox.any_in(prims, ray, counters, &mut occludes);
            occluded |= flow.is_break();
            flow
        });
        occluded
    }
}

#[cfg(test)]
mod tests {
    use glam::Vec3;

    use super::*;
    use crate::accel::{GridParams, WorkCounts};
    use crate::{Aabb, Accel};

    fn cube(c: Vec3, r: f32) -> Aabb {
        Aabb::new(c - Vec3::splat(r), c + Vec3::splat(r))
    }

    fn hit_box(b: &[Aabb]) -> impl Fn(u32, &Ray) -> Option<PrimHit> + '_ {
        |p, r| b[p as usize].intersect(r).map(|(t, _)| PrimHit::at(t))
    }

    /// A 10x10x10 lattice of small cubes, one per cell at lambda 1.
    fn lattice() -> Vec<Aabb> {
        (0..1000).map(|i| cube(Vec3::new((i % 10) as f32, (i / 10 % 10) as f32, (i / 100) as f32) + 0.5, 0.2)).collect()
    }

    fn grid(boxes: &[Aabb]) -> Grid {
        Grid::build_with(boxes, GridParams { lambda: 1.0, ..GridParams::default() })
    }

    #[test]
    fn the_walk_visits_the_cells_along_the_ray_and_stops_at_the_hit() {
        let b = lattice();
        let g = grid(&b);
        assert_eq!(g.resolution(), [10, 10, 10]);
        let mut c = WorkCounts::default();
        // Along a row, from outside: the first cube of the row is hit in the first cell.
        let ray = Ray::new(Vec3::new(-5.0, 3.5, 7.5), Vec3::X);
        assert_eq!(g.closest_hit(&ray, &mut c, hit_box(&b)).map(|h| h.prim), Some(730));
        assert_eq!((c.nodes_visited, c.exact_tests, c.box_tests), (1, 1, 1));
        // Between the rows (through the gaps): no hit, every cell of a line crossed.
        let mut c = WorkCounts::default();
        let gap = Ray::new(Vec3::new(-5.0, 3.0, 7.0), Vec3::X);
        let _ = g.closest_hit(&gap, &mut c, |_, _| None);
        assert!(c.nodes_visited >= 10, "{c:?}");
    }

    #[test]
    fn rays_from_inside_from_the_boundary_and_backwards() {
        let b = lattice();
        let g = grid(&b);
        let cases = [
            (Vec3::new(4.5, 4.5, 4.6), Vec3::Z, 444),
            (Vec3::new(4.5, 4.5, 4.6), -Vec3::Z, 444),
            (Vec3::new(4.5, 4.5, 4.8), Vec3::Z, 544),
            (Vec3::new(10.0, 2.5, 2.5), -Vec3::X, 229),
            (Vec3::new(0.0, 0.0, 0.0), Vec3::ONE, 0),
            (Vec3::new(10.0, 10.0, 10.0), -Vec3::ONE, 999),
            (Vec3::new(9.5, 9.5, 20.0), -Vec3::Z, 999),
        ];
        for (o, d, expected) in cases {
            let hit = g.closest_hit(&Ray::new(o, d), &mut WorkCounts::default(), hit_box(&b));
            assert_eq!(hit.map(|h| h.prim), Some(expected), "from {o} along {d}");
            assert!(g.any_hit(&Ray::new(o, d), &mut WorkCounts::default(), |p, r| hit_box(&b)(p, r).is_some()));
        }
        // Away from everything, from the boundary.
        let away = Ray::new(Vec3::new(10.0, 5.0, 5.0), Vec3::X);
        assert!(g.closest_hit(&away, &mut WorkCounts::default(), hit_box(&b)).is_none());
    }

    #[test]
    fn a_hit_beyond_the_cell_does_not_stop_the_walk() {
        // A row of ten cubes, one per cell. Primitive 0, in the first cell, says it is hit far
        // along the ray (as a primitive straddling many cells would be); primitive 3, three cells
        // on, is hit closer. The walk must not stop at the first hit, nor test 0 again.
        let b: Vec<Aabb> = (0..10).map(|i| cube(Vec3::new(i as f32 + 0.5, 0.5, 0.5), 0.2)).collect();
        let g = grid(&b);
        assert_eq!(g.resolution(), [10, 1, 1]);
        let mut tested = [0u32; 10];
        let ray = Ray::new(Vec3::new(-1.0, 0.5, 0.5), Vec3::X);
        let hit = g.closest_hit(&ray, &mut WorkCounts::default(), |p, r| {
            tested[p as usize] += 1;
            match p {
                0 => Some(PrimHit::at(9.5)),
                3 => hit_box(&b)(p, r),
                _ => None,
            }
        });
        let hit = hit.unwrap();
        assert!(hit.prim == 3 && (hit.t - 4.3).abs() < 1e-5, "{hit:?}");
        assert_eq!(tested, [1, 1, 1, 1, 0, 0, 0, 0, 0, 0], "stops in the cell of the closest hit");
    }

    #[test]
    fn mailboxing_tests_a_long_primitive_once() {
        let mut b = lattice();
        b.push(Aabb::new(Vec3::new(0.0, 0.0, 0.0), Vec3::new(10.0, 0.05, 0.05)));
        let count = |mailbox| {
            let g = Grid::build_with(&b, GridParams { lambda: 1.0, mailbox, ..GridParams::default() });
            let mut tested = 0;
            g.any_hit(&Ray::new(Vec3::new(-1.0, 0.02, 0.02), Vec3::X), &mut WorkCounts::default(), |p, _| {
                tested += (p == 1000) as u32;
                false
            });
            tested
        };
        assert_eq!(count(true), 1);
        assert_eq!(count(false), 10);
    }

    #[test]
    fn degenerate_grids_answer_like_brute_force() {
        // Everything at one point; everything in one plane.
        let point = vec![Aabb::new(Vec3::ONE, Vec3::ONE); 5];
        let g = Grid::build(&point);
        assert_eq!(g.cell_count(), 1);
        let hit = g.closest_hit(&Ray::new(Vec3::ZERO, Vec3::ONE), &mut WorkCounts::default(), hit_box(&point));
        assert_eq!(hit.map(|h| (h.prim, h.t)), Some((0, 1.0)));
        let flat: Vec<Aabb> = (0..100)
            .map(|i| {
                Aabb::new(
                    Vec3::new((i % 10) as f32, (i / 10) as f32, 0.0),
                    Vec3::new((i % 10) as f32 + 0.9, (i / 10) as f32 + 0.9, 0.0),
                )
            })
            .collect();
        let g = Grid::build(&flat);
        assert_eq!(g.resolution()[2], 1);
        for (o, d, expected) in [
            (Vec3::new(3.5, 4.5, 5.0), -Vec3::Z, Some(43)),
            (Vec3::new(-1.0, 4.5, 0.0), Vec3::X, Some(40)),
            (Vec3::new(3.95, -1.0, 0.0), Vec3::Y, None),
            (Vec3::new(3.5, 4.5, 1.0), Vec3::Z, None),
        ] {
            let hit = g.closest_hit(&Ray::new(o, d), &mut WorkCounts::default(), hit_box(&flat));
            assert_eq!(hit.map(|h| h.prim), expected, "from {o} along {d}");
        }
    }

    #[test]
    fn invalid_rays_and_empty_grids_visit_nothing() {
        let b = lattice();
        let g = grid(&b);
        let mut c = WorkCounts::default();
        assert!(g.closest_hit(&Ray::new(Vec3::ZERO, Vec3::ZERO), &mut c, |_, _| Some(PrimHit::at(1.0))).is_none());
        let empty = Grid::build(&[]);
        assert!(!empty.any_hit(&Ray::new(Vec3::ZERO, Vec3::Z), &mut c, |_, _| true));
        assert_eq!(c, WorkCounts::default());
    }
}
