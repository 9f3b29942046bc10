//! Instances that move: after `World::move_instances`, every kind of world answers exactly as a
//! world built from scratch over the moved objects (object, triangle, `t`, `u`, `v` bit for bit,
//! and any-hit), and a refused move changes nothing.

use std::sync::Arc;

use englobe::{
    AccelKind, Affine3A, Instance, NoCount, Object, Plane, Ray, Sphere, TriangleMesh, Vec3, World, WorldError,
};
use glam::{EulerRot, Quat};
use rand::{RngExt, SeedableRng};
use rand_pcg::Pcg32;

/// A bumpy grid of `n x n` quads around the origin.
fn grid(n: u32, seed: u64) -> Arc<TriangleMesh> {
    let mut rng = Pcg32::seed_from_u64(seed);
    let positions =
        (0..=n).flat_map(|j| (0..=n).map(move |i| (i, j))).map(|(i, j)| Vec3::new(i as f32, 0.0, j as f32)).collect();
    let mut positions: Vec<Vec3> = positions;
    for p in &mut positions {
        p.y = rng.random_range(-0.3..0.3);
        *p -= Vec3::new(n as f32 / 2.0, 0.0, n as f32 / 2.0);
    }
    let mut triangles = Vec::new();
    for j in 0..n {
        for i in 0..n {
            let v = |i: u32, j: u32| i + j * (n + 1);
            triangles.push([v(i, j), v(i + 1, j), v(i + 1, j + 1)]);
            triangles.push([v(i, j), v(i + 1, j + 1), v(i, j + 1)]);
        }
    }
    Arc::new(TriangleMesh::new(positions, triangles).unwrap())
}

fn placement(rng: &mut Pcg32) -> Affine3A {
    let rotation = Quat::from_euler(EulerRot::XYZ, rng.random_range(-3.0..3.0), rng.random_range(-3.0..3.0), 0.5);
    let scale = Vec3::new(rng.random_range(0.2..1.0), rng.random_range(0.2..1.0), rng.random_range(0.2..1.0));
    let at = Vec3::new(rng.random_range(-10.0..10.0), rng.random_range(-10.0..10.0), rng.random_range(-10.0..10.0));
    Affine3A::from_scale_rotation_translation(scale, rotation, at)
}

fn objects(rng: &mut Pcg32, meshes: &[Arc<TriangleMesh>], with_plain_mesh: bool) -> Vec<Object> {
    let mut objects: Vec<Object> = Vec::new();
    if with_plain_mesh {
        objects.push(Object::Mesh(grid(6, 99)));
    }
    for i in 0..40 {
        objects.push(Instance::new(meshes[i % meshes.len()].clone(), placement(rng)).unwrap().into());
    }
    objects.push(Sphere::new(Vec3::new(1.0, 2.0, 3.0), 1.5).into());
    objects.push(Plane::new(Vec3::Y, Vec3::new(0.0, -12.0, 0.0)).unwrap().into());
    objects
}

fn rays(rng: &mut Pcg32) -> Vec<Ray> {
    (0..1500)
        .map(|_| {
            let o =
                Vec3::new(rng.random_range(-15.0..15.0), rng.random_range(-15.0..15.0), rng.random_range(-15.0..15.0));
            let target =
                Vec3::new(rng.random_range(-8.0..8.0), rng.random_range(-8.0..8.0), rng.random_range(-8.0..8.0));
            Ray::new(o, (target - o).normalize())
        })
        .collect()
}

fn same_answers(a: &World, b: &World, rays: &[Ray], what: &str) {
    let bits =
        |h: Option<englobe::WorldHit>| h.map(|h| (h.object, h.prim, h.t.to_bits(), h.u.to_bits(), h.v.to_bits()));
    let mut hits = 0;
    for (i, r) in rays.iter().enumerate() {
        let (x, y) = (a.closest_hit(r, &mut NoCount), b.closest_hit(r, &mut NoCount));
        assert_eq!(bits(x), bits(y), "{what}: ray {i}");
        assert_eq!(a.any_hit(r, &mut NoCount), b.any_hit(r, &mut NoCount), "{what}: ray {i}, any hit");
        hits += x.is_some() as u32;
    }
    assert!(hits > 300, "{what}: the rays must hit something ({hits})");
}

#[test]
fn moved_worlds_answer_as_worlds_built_from_scratch() {
    let meshes = [grid(4, 1), grid(3, 2)];
    for &kind in AccelKind::ALL {
        for with_plain_mesh in [false, true] {
            let mut rng = Pcg32::seed_from_u64(7);
            let start = objects(&mut rng, &meshes, with_plain_mesh);
            let mut world = World::build(start.clone(), kind).unwrap();
            let mut moved = start;
            for frame in 0..3 {
                // A few instances move each frame, every one of them in the last.
                let moves: Vec<(usize, Affine3A)> = moved
                    .iter()
                    .enumerate()
                    .filter(|(i, o)| matches!(o, Object::Instance(_)) && (frame == 2 || i % 3 == frame))
                    .map(|(i, _)| (i, placement(&mut rng)))
                    .collect();
                for &(i, to_world) in &moves {
                    let Object::Instance(inst) = &moved[i] else { unreachable!() };
                    moved[i] = Instance::new(inst.mesh().clone(), to_world).unwrap().into();
                }
                world.move_instances(&moves).unwrap();
                let fresh = World::build(moved.clone(), kind).unwrap();
                same_answers(
                    &world,
                    &fresh,
                    &rays(&mut rng),
                    &format!("{kind}, plain mesh {with_plain_mesh}, frame {frame}"),
                );
            }
        }
    }
}

#[test]
fn a_refused_move_changes_nothing() {
    let meshes = [grid(3, 3)];
    let mut rng = Pcg32::seed_from_u64(11);
    let start = objects(&mut rng, &meshes, true);
    let mut world = World::build(start.clone(), AccelKind::BvhWide).unwrap();
    let sphere = start.len() - 2;
    let good = (1, Affine3A::from_translation(Vec3::X));
    let e = world.move_instances(&[good, (sphere, Affine3A::IDENTITY)]).unwrap_err();
    assert!(matches!(e, WorldError::NotAnInstance { object } if object == sphere), "{e}");
    let e = world.move_instances(&[good, (2, Affine3A::from_scale(Vec3::new(1.0, 0.0, 1.0)))]).unwrap_err();
    assert!(e.to_string().starts_with("object 2: the instance transform is singular"), "{e}");
    assert!(matches!(
        world.move_instances(&[(10_000, Affine3A::IDENTITY)]),
        Err(WorldError::NotAnInstance { object: 10_000 })
    ));
    let untouched = World::build(start, AccelKind::BvhWide).unwrap();
    same_answers(&world, &untouched, &rays(&mut rng), "after refused moves");
}

/// `mesh` with every vertex moved a little (the same triangles).
fn jittered(mesh: &TriangleMesh, rng: &mut Pcg32, amount: f32) -> TriangleMesh {
    let positions = mesh
        .positions()
        .iter()
        .map(|p| {
            *p + Vec3::new(
                rng.random_range(-amount..amount),
                rng.random_range(-amount..amount),
                rng.random_range(-amount..amount),
            )
        })
        .collect();
    TriangleMesh::new(positions, mesh.triangles().to_vec()).unwrap()
}

#[test]
fn refitted_worlds_answer_as_worlds_built_from_scratch() {
    let meshes = [grid(4, 1), grid(3, 2)];
    for &kind in AccelKind::ALL {
        let mut rng = Pcg32::seed_from_u64(13);
        let start = objects(&mut rng, &meshes, true);
        let mut world = World::build(start.clone(), kind).unwrap();
        let mut moved = start;
        for frame in 0..3 {
            // The plain mesh (object 0) deforms, and so does the first instanced mesh.
            let Object::Mesh(plain) = &moved[0] else { unreachable!() };
            let plain = jittered(plain, &mut rng, 0.4);
            moved[0] = Object::Mesh(Arc::new(plain.clone()));
            let report = world.refit_mesh(0, plain).unwrap();
            // The fast path refits its tree; the teaching structures are built again.
            match kind {
                AccelKind::BvhWide => assert!(!report.rebuilt && report.sah_cost > 0.0, "{kind}: {report:?}"),
                _ => assert!(report.rebuilt, "{kind}: {report:?}"),
            }

            let Object::Instance(first) = &moved[1] else { unreachable!() };
            let placed = first.mesh().clone();
            let new_mesh = Arc::new(jittered(&placed, &mut rng, 0.3));
            for o in &mut moved {
                if let Object::Instance(inst) = o
                    && Arc::ptr_eq(inst.mesh(), &placed)
                {
                    *o = Instance::new(new_mesh.clone(), *inst.to_world()).unwrap().into();
                }
            }
            world.refit_instanced_mesh(&placed, new_mesh).unwrap();
            let fresh = World::build(moved.clone(), kind).unwrap();
            same_answers(&world, &fresh, &rays(&mut rng), &format!("{kind}, refit frame {frame}"));
        }
    }
}

#[test]
fn refits_of_other_triangles_or_objects_are_refused() {
    let meshes = [grid(3, 3)];
    let mut rng = Pcg32::seed_from_u64(17);
    let start = objects(&mut rng, &meshes, true);
    let mut world = World::build(start.clone(), AccelKind::BvhWide).unwrap();
    let Object::Mesh(plain) = &start[0] else { unreachable!() };
    let mut flipped = plain.triangles().to_vec();
    flipped[0].swap(1, 2);
    let other = TriangleMesh::new(plain.positions().to_vec(), flipped).unwrap();
    assert!(matches!(world.refit_mesh(0, other.clone()), Err(WorldError::OtherTriangles { object: 0 })));
    assert!(matches!(world.refit_mesh(1, other.clone()), Err(WorldError::NotAMesh { object: 1 })));
    assert!(matches!(world.refit_instanced_mesh(plain, Arc::new(other)), Err(WorldError::NotInstanced)));
    let fewer = TriangleMesh::new(meshes[0].positions().to_vec(), meshes[0].triangles()[1..].to_vec()).unwrap();
    assert!(matches!(
        world.refit_instanced_mesh(&meshes[0], Arc::new(fewer)),
        Err(WorldError::OtherInstancedTriangles)
    ));
    let untouched = World::build(start, AccelKind::BvhWide).unwrap();
    same_answers(&world, &untouched, &rays(&mut rng), "after refused refits");
}
