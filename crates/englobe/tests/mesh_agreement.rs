//! Every structure of `AccelKind::ALL` against brute force on real meshes from the shared data
//! folder (the Stanford bunny, the Utah teapot): valid trees, the same closest hit and any-hit
//! answer for rays from all around, and less work than brute force. Then the quality of the
//! trees on the bunny and the Sponza atrium: the SAH costs of the builders against the full
//! sweep's, which the documentation quotes.

mod common;

use common::rng::{ray_into_box, seeded};
use common::{check_all_structures_clipped, load_obj};
use englobe::accel::bvh::validate_bvh;
use englobe::shapes::clip_triangle;
use englobe::{Aabb, Accel, AccelKind, AnyAccel, NoCount, Ray, Vec3, WorkCounts};

/// Deterministic rays from a sphere around `bounds` towards points inside it, plus axis-parallel
/// rays on a grid across it.
fn rays_around(bounds: Aabb, count: usize) -> Vec<Ray> {
    let mut rng = seeded(0x2545_f491_4f6c_dd1d);
    let extent = bounds.extent();
    let mut rays = Vec::with_capacity(count + 108);
    rays.extend((0..count).map(|_| ray_into_box(&mut rng, &bounds)));
    for axis in 0..3 {
        for i in 0..6 {
            for j in 0..6 {
                let mut o = bounds.min + extent * Vec3::splat((i as f32 + 0.5) / 6.0);
                o[(axis + 1) % 3] = bounds.min[(axis + 1) % 3] + extent[(axis + 1) % 3] * (j as f32 + 0.5) / 6.0;
                o[axis] = bounds.min[axis] - 1.0;
                let mut d = Vec3::ZERO;
                d[axis] = 1.0;
                rays.push(Ray::new(o, d));
            }
        }
    }
    rays
}

fn check_mesh(relative: &str, rays: usize) {
    let mesh = load_obj(relative);
    let boxes: Vec<Aabb> = (0..mesh.len() as u32).map(|t| mesh.triangle_bounds(t)).collect();
    let rays = rays_around(mesh.bounds(), rays);
    let clip = |i: u32, cell: &Aabb| clip_triangle(mesh.triangle(i).vertices, cell);
    check_all_structures_clipped(&boxes, &clip, &rays, |i, r| mesh.intersect(i, r))
        .unwrap_or_else(|e| panic!("{relative}: {e}"));

    // Work: the ordered traversal never tests more than the report's, which never tests more
    // than brute force; on a real mesh both test far fewer.
    let tests = |kind| {
        let accel = AnyAccel::build(kind, &boxes);
        let mut c = WorkCounts::default();
        for r in &rays {
            accel.closest_hit(r, &mut c, |i, r| mesh.intersect(i, r));
        }
        c.exact_tests
    };
    let (none, seed, ordered) = (tests(AccelKind::None), tests(AccelKind::BvhSeed), tests(AccelKind::BvhSeedOrdered));
    assert_eq!(none, (mesh.len() * rays.len()) as u64);
    assert!(ordered < seed && seed * 10 < none, "{relative}: exact tests none {none}, seed {seed}, ordered {ordered}");
    // The SAH trees visit a small fraction of the seed tree's nodes.
    let visits = |kind| {
        let accel = AnyAccel::build(kind, &boxes);
        let mut c = WorkCounts::default();
        for r in &rays {
            accel.closest_hit(r, &mut c, |i, r| mesh.intersect(i, r));
        }
        c.nodes_visited
    };
    let (seed_visits, sah_visits) = (visits(AccelKind::BvhSeedOrdered), visits(AccelKind::BvhSah));
    assert!(sah_visits * 10 < seed_visits, "{relative}: nodes visited: bvh-sah {sah_visits}, seed {seed_visits}");
    // The rays do hit the mesh, often enough for the comparison to mean something.
    let bvh = AnyAccel::build(AccelKind::BvhSeedOrdered, &boxes);
    let hits = rays.iter().filter(|r| bvh.closest_hit(r, &mut NoCount, |i, r| mesh.intersect(i, r)).is_some()).count();
    assert!(hits * 4 > rays.len(), "{relative}: only {hits} of {} rays hit", rays.len());
}

#[test]
fn stanford_bunny() {
    check_mesh("scenes/meshes/bunny/stanford-bunny.obj", 150);
}

#[test]
fn utah_teapot() {
    check_mesh("scenes/meshes/teapot/teapot.obj", 600);
}

/// SAH costs of bvh-sah, bvh-ploc and bvh-sweep on a mesh, and the seed tree's.
fn sah_costs(relative: &str) -> [f32; 4] {
    let mesh = load_obj(relative);
    let boxes: Vec<Aabb> = (0..mesh.len() as u32).map(|t| mesh.triangle_bounds(t)).collect();
    [AccelKind::BvhSah, AccelKind::BvhPloc, AccelKind::BvhSweep, AccelKind::BvhSeed].map(|kind| {
        let accel = AnyAccel::build(kind, &boxes);
        validate_bvh(accel.bvh().unwrap(), &boxes).unwrap_or_else(|e| panic!("{relative}, {kind}: {e}")).sah_cost
    })
}

#[test]
fn binned_sah_is_within_5_percent_and_ploc_within_10_percent_of_the_full_sweep() {
    for relative in ["scenes/meshes/bunny/stanford-bunny.obj", "scenes/meshes/sponza-dabrovic/sponza.obj"] {
        let [sah, ploc, sweep, seed] = sah_costs(relative);
        assert!(sah <= sweep * 1.05, "{relative}: bvh-sah {sah}, bvh-sweep {sweep}");
        assert!(ploc <= sweep * 1.10, "{relative}: bvh-ploc {ploc}, bvh-sweep {sweep}");
        assert!(sweep * 50.0 < seed, "{relative}: bvh-sweep {sweep}, bvh-seed {seed}");
    }
}
