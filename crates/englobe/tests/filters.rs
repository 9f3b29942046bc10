//! Hit filters against worlds without what they reject: a filter that rejects some triangles of
//! a mesh answers as the same world with those triangles flattened to a point (never hit, same
//! numbering), and one that rejects whole objects as the world with those objects moved out of
//! every ray's way; closest hit and any hit, on the fast path and the teaching structures, and on
//! [`TriangleBvh`] alone against brute force.

mod common;

use std::sync::Arc;

use common::rng::{in_box, ray_into_box, seeded};
use englobe::shapes::{WatertightRay, intersect_triangle};
use englobe::{
    Aabb, AccelKind, Affine3A, Hit, Instance, NoCount, Object, Plane, Ray, Sphere, TriangleBvh, TriangleMesh, Vec3,
    World, WorldHit,
};

/// A soup of small triangles in the unit cube.
fn soup(n: usize, seed: u64) -> Vec<[Vec3; 3]> {
    let mut rng = seeded(seed);
    let unit = Aabb::new(Vec3::ZERO, Vec3::ONE);
    (0..n)
        .map(|_| {
            let a = in_box(&mut rng, &unit);
            [a, a + (in_box(&mut rng, &unit) - 0.5) * 0.3, a + (in_box(&mut rng, &unit) - 0.5) * 0.3]
        })
        .collect()
}

fn mesh(tris: &[[Vec3; 3]]) -> TriangleMesh {
    let vertices: Vec<Vec3> = tris.iter().flatten().copied().collect();
    TriangleMesh::new(vertices, (0..tris.len() as u32).map(|i| [3 * i, 3 * i + 1, 3 * i + 2]).collect()).unwrap()
}

fn rejected(object: u32, prim: u32) -> bool {
    object == 2 || (object == 1 && prim.is_multiple_of(3))
}

/// Object 1's triangles that `rejected` names flattened, object 2 moved far away.
fn objects(filtered_out: bool) -> Vec<Object> {
    let tris = soup(600, 0xf117);
    let flat: Vec<[Vec3; 3]> = tris
        .iter()
        .enumerate()
        .map(|(i, t)| if rejected(1, i as u32) && filtered_out { [t[0]; 3] } else { *t })
        .collect();
    let shared = Arc::new(mesh(&soup(300, 0x5ad)));
    let away = Affine3A::from_translation(Vec3::splat(1e4));
    vec![
        Sphere::new(Vec3::new(0.5, 0.5, -1.0), 0.4).into(),
        mesh(&flat).into(),
        Instance::new(shared.clone(), if filtered_out { away } else { Affine3A::from_translation(Vec3::X * 0.5) })
            .unwrap()
            .into(),
        Instance::new(shared, Affine3A::from_translation(-Vec3::X * 0.5)).unwrap().into(),
        Plane::new(Vec3::Y, Vec3::new(0.0, -0.5, 0.0)).unwrap().into(),
    ]
}

#[test]
fn a_filtered_world_answers_as_the_world_without_what_it_rejects() {
    let bounds = Aabb::new(Vec3::new(-1.0, -0.6, -1.5), Vec3::new(2.0, 1.5, 1.5));
    let mut rng = seeded(0xf11e_7e55);
    let rays: Vec<Ray> = (0..4000).map(|_| ray_into_box(&mut rng, &bounds)).collect();
    for kind in [AccelKind::BvhWide, AccelKind::BvhSah, AccelKind::KdTree, AccelKind::None] {
        let world = World::build(objects(false), kind).unwrap();
        let without = World::build(objects(true), kind).unwrap();
        let (mut changed, mut hits) = (0, 0);
        for ray in &rays {
            let mut calls = 0;
            let got = world.closest_hit_filtered(ray, &mut NoCount, |h: &WorldHit| {
                calls += 1;
                !rejected(h.object, h.prim)
            });
            let expected = without.closest_hit(ray, &mut NoCount);
            assert_eq!(got, expected, "{kind}: {ray:?}");
            let any = world.any_hit_filtered(ray, &mut NoCount, |h: &WorldHit| !rejected(h.object, h.prim));
            assert_eq!(any, expected.is_some(), "{kind}: {ray:?}");
            assert!(calls > 0 || world.closest_hit(ray, &mut NoCount).is_none());
            changed += (world.closest_hit(ray, &mut NoCount) != expected) as usize;
            hits += expected.is_some() as usize;
        }
        assert!(changed > 200 && hits > 2000, "{kind}: the filter changed {changed} answers, {hits} hits");
    }
}

#[test]
fn a_filtered_triangle_bvh_agrees_with_brute_force() {
    let tris = soup(2000, 0xb17e);
    let bvh = TriangleBvh::from_triangles(&tris);
    let keep = |h: &Hit| h.prim % 4 != 1 && h.t > 0.25;
    let mut rng = seeded(0xb0b);
    let bounds = Aabb::new(Vec3::ZERO, Vec3::ONE);
    let mut hits = 0;
    for _ in 0..3000 {
        let ray = ray_into_box(&mut rng, &bounds);
        let w = WatertightRay::new(&ray);
        let mut best: Option<Hit> = None;
        let mut any = false;
        for (i, [a, b, c]) in tris.iter().enumerate() {
            if let Some(h) = intersect_triangle(&ray, &w, *a, *b, *c) {
                let h = Hit { t: h.t, prim: i as u32, u: h.u, v: h.v };
                if keep(&h) {
                    any = true;
                    if best.is_none_or(|b| h.t < b.t) {
                        best = Some(h);
                    }
                }
            }
        }
        assert_eq!(bvh.closest_hit_filtered(&ray, &mut NoCount, keep), best, "{ray:?}");
        assert_eq!(bvh.any_hit_filtered(&ray, &mut NoCount, keep), any, "{ray:?}");
        hits += any as usize;
    }
    assert!(hits > 1000, "{hits}");
}
