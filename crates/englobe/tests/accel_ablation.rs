//! What the kd-tree's and the grid's choices are worth, in work per ray on real meshes: the SAH
//! costs and the empty space bonus of the kd-tree, exact triangle clipping against box clipping,
//! mailboxing on and off, and the grid's density `lambda`. Figures, not checks: ignored by default,
//! printed by
//!
//! ```sh
//! cargo test --release -p englobe --test accel_ablation -- --ignored --nocapture
//! ```
//!
//! (`docs/accelerators.md` quotes them). Rays come from a sphere around each mesh towards random
//! points of its box, so about half of them hit it.

mod common;

use common::load_obj;
use common::rng::{in_cube, ray_into_box, seeded, unit_vec3};
use englobe::accel::grid::stats::validate_grid_clipped;
use englobe::accel::kdtree::stats::validate_kdtree;
use englobe::accel::{Grid, GridParams, KdTree, KdTreeParams};
use englobe::shapes::clip_triangle;
use englobe::{Aabb, Accel, AccelKind, AnyAccel, Ray, TriangleMesh, Vec3, WorkCounts};

/// `n` random triangles of size `size` with centres in the cube `[-half, half]^3`.
fn soup(n: usize, half: f32, size: f32) -> TriangleMesh {
    let mut rng = seeded(0x9e37_79b9_7f4a_7c15);
    let mut positions = Vec::with_capacity(3 * n);
    for _ in 0..n {
        let c = in_cube(&mut rng) * half;
        for _ in 0..3 {
            positions.push(c + (unit_vec3(&mut rng) - Vec3::splat(0.5)) * size);
        }
    }
    let triangles = (0..n as u32).map(|i| [3 * i, 3 * i + 1, 3 * i + 2]).collect();
    TriangleMesh::new(positions, triangles).unwrap()
}

fn rays_around(bounds: Aabb, count: usize) -> Vec<Ray> {
    let mut rng = seeded(0x2545_f491_4f6c_dd1d);
    (0..count).map(|_| ray_into_box(&mut rng, &bounds)).collect()
}

fn work(accel: &impl Accel, mesh: &TriangleMesh, rays: &[Ray]) -> (f64, f64) {
    let mut c = WorkCounts::default();
    for r in rays {
        accel.closest_hit(r, &mut c, |i, r| mesh.intersect(i, r));
    }
    let n = rays.len() as f64;
    (c.exact_tests as f64 / n, c.nodes_visited as f64 / n)
}

// Ignored: it builds some twenty variants over four meshes (minutes, even in release) to print
// the figures docs/accelerators.md quotes, and checks nothing the other tests do not; run it by
// hand with the command at the top of this file.
#[test]
#[ignore = "figures for docs/accelerators.md, not a check"]
fn print_the_figures() {
    for relative in [
        "uniform soup",
        "scenes/meshes/bunny/stanford-bunny.obj",
        "scenes/meshes/sponza-dabrovic/sponza.obj",
        "scenes/meshes/teapot/teapot.obj",
    ] {
        let mesh = if relative == "uniform soup" { soup(100_000, 10.0, 0.5) } else { load_obj(relative) };
        let boxes: Vec<Aabb> = (0..mesh.len() as u32).map(|t| mesh.triangle_bounds(t)).collect();
        let rays = rays_around(mesh.bounds(), 20_000);
        let exact = |i: u32, c: &Aabb| clip_triangle(mesh.triangle(i).vertices, c);
        let boxed = |i: u32, c: &Aabb| boxes[i as usize].intersection(c);
        println!("\n{relative}: {} triangles, {} rays", mesh.len(), rays.len());
        for &kind in AccelKind::ALL.iter().filter(|&&k| k != AccelKind::None && k != AccelKind::BvhSeed) {
            let (tests, nodes) = work(&AnyAccel::build_with_clipper(kind, &boxes, &exact), &mesh, &rays);
            println!("  {:<40} tests/ray {tests:7.2}  nodes/ray {nodes:7.2}", kind.name());
        }
        let base = KdTreeParams::default();
        let variants = [
            ("kdtree (defaults: K_T 1, K_I 20)", base, true),
            ("kdtree, box clipping", base, false),
            ("kdtree, no mailbox", KdTreeParams { mailbox: false, ..base }, true),
            ("kdtree, no empty space bonus", KdTreeParams { empty_bonus: 0.0, ..base }, true),
            ("kdtree, K_I 1.5", KdTreeParams { intersection_cost: 1.5, ..base }, true),
            ("kdtree, K_I 5", KdTreeParams { intersection_cost: 5.0, ..base }, true),
            (
                "kdtree, K_I 80, bonus 0.5 (pbrt)",
                KdTreeParams { intersection_cost: 80.0, empty_bonus: 0.5, ..base },
                true,
            ),
            ("kdtree, K_T 15, K_I 20 (Wald-Havran)", KdTreeParams { traversal_cost: 15.0, ..base }, true),
            (
                "kdtree, depth limit + 3",
                KdTreeParams { max_depth: Some(base.depth_limit(mesh.len()) + 3), ..base },
                true,
            ),
        ];
        for (name, params, exact_clip) in variants {
            let start = std::time::Instant::now();
            let tree = if exact_clip {
                KdTree::build_with_clipper(&boxes, &exact, params)
            } else {
                KdTree::build_with_clipper(&boxes, &boxed, params)
            };
            let seconds = start.elapsed().as_secs_f64();
            let q = validate_kdtree(&tree, &boxes).unwrap();
            let (tests, nodes) = work(&tree, &mesh, &rays);
            println!(
                "  {name:<40} tests/ray {tests:7.2}  nodes/ray {nodes:7.2}  refs/prim {:.2}  depth {}  nodes {}  SAH {:.1}  build {seconds:.2} s",
                q.refs_per_prim,
                q.depth,
                q.interior + q.leaves,
                q.sah_cost
            );
        }
        for (lambda, mailbox, exact_clip) in [
            (1.0, true, true),
            (2.0, true, true),
            (3.0, true, true),
            (3.0, false, true),
            (3.0, true, false),
            (4.0, true, true),
        ] {
            let params = GridParams { lambda, mailbox, ..GridParams::default() };
            let grid = if exact_clip {
                Grid::build_with_clipper(&boxes, &exact, params)
            } else {
                Grid::build_with(&boxes, params)
            };
            let q = validate_grid_clipped(&grid, &boxes, Some(&exact)).unwrap();
            let (tests, nodes) = work(&grid, &mesh, &rays);
            let variant = match (mailbox, exact_clip) {
                (false, _) => ", no mailbox",
                (_, false) => ", box clipping",
                _ => "",
            };
            println!(
                "  grid, lambda {lambda}{variant:<26} tests/ray {tests:7.2}  cells/ray {nodes:7.2}  refs/prim {:.2}  cells {} ({:?})",
                q.refs_per_prim, q.cells, q.resolution
            );
        }
    }
}
