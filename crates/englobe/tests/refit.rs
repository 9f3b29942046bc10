//! [`TriangleBvh::refit`] against brute force and against a structure built afresh over the
//! moved vertices: the same closest hit (triangle, `t`, barycentrics, bit for bit) and the same
//! any-hit answer, the validator's invariants, and the SAH cost it reports. Random meshes whose
//! vertices all move by small random offsets (some triangles flattening or unflattening, which
//! makes the structure rebuild), and the Stanford bunny.

mod common;

use common::load_obj;
use common::rng::{in_cube, ray_into_box, seeded};
use englobe::accel::Validate;
use englobe::accel::wide::RefitError;
use englobe::shapes::{MeshError, WatertightRay, intersect_triangle};
use englobe::{Aabb, Hit, NoCount, Ray, TriangleBvh, Vec3};
use proptest::prelude::*;

/// The closest hit by testing every triangle, ties to the lower index, and the any-hit answer.
fn brute(tris: &[[Vec3; 3]], ray: &Ray) -> (Option<Hit>, bool) {
    let w = WatertightRay::new(ray);
    let mut best: Option<Hit> = None;
    for (i, [a, b, c]) in tris.iter().enumerate() {
        let t_max = best.map_or(ray.t_max, |h| h.t);
        if let Some(h) = intersect_triangle(&ray.with_range(ray.t_min, t_max), &w, *a, *b, *c)
            && best.is_none_or(|b| h.t < b.t)
        {
            best = Some(Hit { t: h.t, prim: i as u32, u: h.u, v: h.v });
        }
    }
    (best, best.is_some())
}

fn triangles(vertices: &[[f32; 3]], indices: &[[u32; 3]]) -> Vec<[Vec3; 3]> {
    indices.iter().map(|t| t.map(|i| Vec3::from_array(vertices[i as usize]))).collect()
}

/// Refits a structure built over `vertices` to `moved`, then checks it on `rays` against brute
/// force and a fresh build; returns the report and the number of rays that hit.
fn check(
    vertices: &[[f32; 3]],
    moved: &[[f32; 3]],
    indices: &[[u32; 3]],
    rays: &[Ray],
) -> Result<(englobe::accel::wide::RefitReport, usize), String> {
    let mut bvh = TriangleBvh::from_arrays(vertices, indices).map_err(|e| e.to_string())?;
    let report = bvh.refit_arrays(moved, indices).map_err(|e| e.to_string())?;
    let fresh = TriangleBvh::from_arrays(moved, indices).map_err(|e| e.to_string())?;
    let tris = triangles(moved, indices);
    let boxes: Vec<Aabb> = tris.iter().map(|t| Aabb::from_points(*t)).collect();
    bvh.validate(&boxes, None).map_err(|e| format!("refitted: {e}"))?;
    if (report.sah_cost - bvh.sah_cost()).abs() > 0.0 {
        return Err(format!("report {report:?}, tree {}", bvh.sah_cost()));
    }
    let mut hits = 0;
    for ray in rays {
        let (closest, any) = brute(&tris, ray);
        let got = bvh.closest_hit(ray, &mut NoCount);
        if got != closest || fresh.closest_hit(ray, &mut NoCount) != closest {
            return Err(format!("{ray:?}: brute force {closest:?}, refitted {got:?}"));
        }
        if bvh.any_hit(ray, &mut NoCount) != any || fresh.any_hit(ray, &mut NoCount) != any {
            return Err(format!("any hit of {ray:?}: brute force {any}"));
        }
        hits += any as usize;
    }
    Ok((report, hits))
}

/// A random mesh: vertices in a cube, triangles over nearby vertices (so they are small), some
/// of them repeating a vertex (zero area).
fn mesh() -> impl Strategy<Value = (Vec<[f32; 3]>, Vec<[u32; 3]>)> {
    (3usize..200).prop_flat_map(|n| {
        let vertices = prop::collection::vec(prop::array::uniform3(-4.0f32..4.0), n);
        let n = n as u32;
        let tri = (0..n, 1..6u32, 1..6u32, 0..10u32).prop_map(move |(a, db, dc, flat)| {
            let (b, c) = ((a + db) % n, (a + db + dc) % n);
            if flat == 0 { [a, b, a] } else { [a, b, c] }
        });
        (vertices, prop::collection::vec(tri, 1..300))
    })
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(64))]

    #[test]
    fn refitted_random_meshes_agree_with_brute_force_and_a_fresh_build(
        (vertices, indices) in mesh(),
        offsets in prop::collection::vec(prop::array::uniform3(-0.3f32..0.3), 200),
        snap in 0u32..4,
        rng_seed in any::<u64>(),
    ) {
        // Every vertex moves; with `snap == 0`, some vertices also land on others (flattening
        // triangles, which must make the structure rebuild).
        let moved: Vec<[f32; 3]> = vertices
            .iter()
            .enumerate()
            .map(|(i, v)| {
                if snap == 0 && i % 5 == 1 { return vertices[i - 1] }
                let o = offsets[i % offsets.len()];
                [v[0] + o[0], v[1] + o[1], v[2] + o[2]]
            })
            .collect();
        let mut rng = seeded(rng_seed);
        let bounds = Aabb::new(Vec3::splat(-4.5), Vec3::splat(4.5));
        let rays: Vec<Ray> = (0..60).map(|_| ray_into_box(&mut rng, &bounds)).collect();
        let (report, _) = check(&vertices, &moved, &indices, &rays).map_err(TestCaseError::fail)?;
        // Moved off every other vertex, no triangle flattens or unflattens: a true refit.
        prop_assert!(snap == 0 || !report.rebuilt, "{:?}", report);
    }
}

#[test]
fn flattening_a_triangle_rebuilds_and_a_refit_keeps_the_instruction_set() {
    let vertices =
        [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [5.0, 5.0, 5.0], [6.0, 5.0, 5.0], [5.0, 6.0, 5.0]];
    let indices = [[0, 1, 2], [3, 4, 5]];
    let mut flat = vertices;
    flat[5] = [7.0, 5.0, 5.0];
    let ray = Ray::new(Vec3::new(0.2, 0.2, 1.0), -Vec3::Z);
    let (report, hits) = check(&vertices, &flat, &indices, &[ray]).unwrap();
    assert!(report.rebuilt && hits == 1, "{report:?}");
    // And back: the flat triangle was left out, it must come back.
    let (report, _) = check(&flat, &vertices, &indices, &[ray]).unwrap();
    assert!(report.rebuilt, "{report:?}");
    let mut bvh = TriangleBvh::from_arrays(&vertices, &indices).unwrap();
    let isa = englobe::accel::wide::Isa::Portable;
    bvh.set_isa(isa).unwrap();
    bvh.refit_arrays(&flat, &indices).unwrap();
    assert_eq!(bvh.isa(), isa);
}

#[test]
fn bad_refits_are_refused_and_change_nothing() {
    let vertices = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]];
    let mut bvh = TriangleBvh::from_arrays(&vertices, &[[0, 1, 2]]).unwrap();
    let before = bvh.clone();
    assert_eq!(
        bvh.refit_arrays(&vertices, &[[0, 1, 2], [0, 2, 1]]),
        Err(RefitError::TriangleCount { built: 1, given: 2 })
    );
    let nan = [[0.0, 0.0, 0.0], [f32::NAN, 0.0, 0.0], [0.0, 1.0, 0.0]];
    assert!(matches!(
        bvh.refit_arrays(&nan, &[[0, 1, 2]]),
        Err(RefitError::Mesh(MeshError::NonFiniteVertex { vertex: 1, .. }))
    ));
    assert!(matches!(
        bvh.refit_arrays(&vertices, &[[0, 1, 9]]),
        Err(RefitError::Mesh(MeshError::IndexOutOfRange { .. }))
    ));
    assert_eq!(bvh.nodes(), before.nodes());
    assert_eq!(bvh.blocks(), before.blocks());
}

#[test]
fn the_moved_bunny_agrees_with_brute_force_and_a_fresh_build() {
    let mesh = load_obj("scenes/meshes/bunny/stanford-bunny.obj");
    let vertices: Vec<[f32; 3]> = mesh.positions().iter().map(|p| p.to_array()).collect();
    let bounds = mesh.bounds();
    let step = bounds.extent().length() * 0.005;
    let mut rng = seeded(0xb0_0bb1e5);
    let moved: Vec<[f32; 3]> = mesh.positions().iter().map(|&p| (p + in_cube(&mut rng) * step).to_array()).collect();
    let rays: Vec<Ray> = (0..3000)
        .map(|i| {
            if i % 2 == 0 {
                ray_into_box(&mut rng, &bounds)
            } else {
                Ray::new(bounds.center() + in_cube(&mut rng) * 0.1 * step, in_cube(&mut rng))
            }
        })
        .collect();
    let (report, hits) = check(&vertices, &moved, mesh.triangles(), &rays).unwrap();
    assert!(hits > 1500, "{hits} hits");
    // Small moves loosen the tree a little, never tighten it below a fraction of a fresh build.
    let fresh = TriangleBvh::from_arrays(&moved, mesh.triangles()).unwrap();
    let ratio = report.sah_cost / fresh.sah_cost();
    assert!(!report.rebuilt && (0.9..1.5).contains(&ratio), "{report:?}, fresh {}", fresh.sah_cost());
    assert!(report.cost_ratio() > 0.9, "{report:?}");
}

#[test]
fn the_built_cost_is_the_tree_as_built_across_refits() {
    // A 10 x 10 grid of small triangles, then the same triangles lifted by uneven heights twice:
    // each refit loosens the boxes, and the cost as built must stay the first tree's.
    let grid = |lift: u32| -> Vec<[f32; 3]> {
        (0..100u32)
            .flat_map(|k| {
                let (x, y, z) = ((k % 10) as f32, (k / 10) as f32, ((k * lift) % 13) as f32);
                [[x, y, z], [x + 0.5, y, z], [x, y + 0.5, z + 0.25]]
            })
            .collect()
    };
    let triangles: Vec<[u32; 3]> = (0..100u32).map(|k| [3 * k, 3 * k + 1, 3 * k + 2]).collect();
    let mut bvh = TriangleBvh::from_arrays(&grid(0), &triangles).unwrap();
    let as_built = bvh.sah_cost();
    assert_eq!(bvh.built_sah_cost(), as_built);
    for lift in [7, 11] {
        let report = bvh.refit_arrays(&grid(lift), &triangles).unwrap();
        assert!(!report.rebuilt);
        assert_eq!((report.built_sah_cost, bvh.built_sah_cost()), (as_built, as_built));
        assert_eq!(report.sah_cost, bvh.sah_cost());
        assert!(report.cost_ratio() > 1.5, "{report:?}");
    }
}
