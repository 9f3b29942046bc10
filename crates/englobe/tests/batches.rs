//! Batch queries against the single-ray ones: [`World::closest_hits`] and [`World::any_hits`]
//! (and [`TriangleBvh`]'s) give, ray for ray, what [`World::closest_hit`] and [`World::any_hit`]
//! give, below the parallel threshold and above it, with invalid rays among them; output slices
//! of the wrong length are refused.

mod common;

use std::sync::Arc;

use common::load_obj;
use common::rng::{ray_into_box, seeded};
use englobe::accel::{BatchSizeMismatch, PARALLEL_BATCH};
use englobe::{AccelKind, Affine3A, Instance, NoCount, Object, Ray, Sphere, TriangleBvh, Vec3, World};

fn rays(n: usize, world: &World, seed: u64) -> Vec<Ray> {
    let mut rng = seeded(seed);
    let bounds = world.bounds();
    (0..n)
        .map(|i| match i % 97 {
            0 => Ray::new(Vec3::ZERO, Vec3::new(f32::NAN, 0.0, 1.0)),
            1 => Ray::segment(bounds.center(), Vec3::X, 0.0, 0.0),
            _ => ray_into_box(&mut rng, &bounds),
        })
        .collect()
}

#[test]
fn batches_answer_as_single_rays_do() {
    let bunny = Arc::new(load_obj("scenes/meshes/bunny/stanford-bunny.obj"));
    let b = bunny.bounds();
    let objects: Vec<Object> = vec![
        Object::Mesh(bunny.clone()),
        Instance::new(bunny.clone(), Affine3A::from_translation(Vec3::X * b.extent().x * 1.2)).unwrap().into(),
        Sphere::new(b.center() - Vec3::X * b.extent().x, b.extent().y * 0.3).into(),
    ];
    for kind in [AccelKind::BvhWide, AccelKind::BvhSah] {
        let world = World::build(objects.clone(), kind).unwrap();
        for n in [0, 1, 300, PARALLEL_BATCH, 20_000] {
            let rays = rays(n, &world, 0x0ba7_c4e5 + n as u64);
            let mut hits = vec![None; n];
            let mut mask = vec![false; n];
            world.closest_hits(&rays, &mut hits).unwrap();
            world.any_hits(&rays, &mut mask).unwrap();
            for (i, r) in rays.iter().enumerate() {
                assert_eq!(hits[i], world.closest_hit(r, &mut NoCount), "{kind}, ray {i} of {n}");
                assert_eq!(mask[i], world.any_hit(r, &mut NoCount), "{kind}, ray {i} of {n}");
            }
            let found = hits.iter().filter(|h| h.is_some()).count();
            assert!(n < 300 || (found > n / 4 && found < n), "{kind}: {found} hits of {n}");
            assert_eq!(found, mask.iter().filter(|&&m| m).count());
        }
    }
}

#[test]
fn triangle_bvh_batches_answer_as_single_rays_do() {
    let mesh = load_obj("scenes/meshes/bunny/stanford-bunny.obj");
    let bvh = TriangleBvh::build(&mesh);
    let mut rng = seeded(0x7e57);
    let rays: Vec<Ray> = (0..10_000).map(|_| ray_into_box(&mut rng, &mesh.bounds())).collect();
    let mut hits = vec![None; rays.len()];
    let mut mask = vec![true; rays.len()];
    bvh.closest_hits(&rays, &mut hits).unwrap();
    bvh.any_hits(&rays, &mut mask).unwrap();
    for (i, r) in rays.iter().enumerate() {
        assert_eq!(hits[i], bvh.closest_hit(r, &mut NoCount));
        assert_eq!(mask[i], hits[i].is_some());
    }
    assert!(hits.iter().filter(|h| h.is_some()).count() > 2500);
}

#[test]
fn outputs_of_the_wrong_length_are_refused() {
    let world = World::build(vec![Sphere::new(Vec3::Z * 5.0, 1.0).into()], AccelKind::BvhWide).unwrap();
    let rays = [Ray::new(Vec3::ZERO, Vec3::Z); 3];
    let mut hits = vec![None; 2];
    assert_eq!(world.closest_hits(&rays, &mut hits), Err(BatchSizeMismatch { rays: 3, outputs: 2 }));
    assert_eq!(hits, vec![None, None], "nothing written");
    let mut mask = vec![false; 4];
    assert_eq!(world.any_hits(&rays, &mut mask), Err(BatchSizeMismatch { rays: 3, outputs: 4 }));
    let bvh = TriangleBvh::from_triangles(&[[Vec3::ZERO, Vec3::X, Vec3::Y]]);
    assert!(bvh.any_hits(&rays, &mut mask).is_err());
}
