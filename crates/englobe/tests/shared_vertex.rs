//! Rays aimed exactly at a vertex shared by a fan of triangles, where the vertex lies on the faces
//! of the triangles' boxes (and so on the faces of every node box above them): every structure
//! must report a hit. The slab test's exit distance is widened by [`ROBUST_FAR_SCALE`] for exactly
//! this case (Ize 2013, "Robust BVH Ray Traversal"): a ray touching a box only at a corner or
//! along a face computes its entry and exit distances with independent roundings, and without the
//! widening the entry can come out past the exit. The last test shows the widening is what makes
//! the box test keep these hits: switched off, the box of a triangle hit at the apex is rejected
//! for some of the same rays.

mod common;

use common::rng::{in_cube, seeded};
use englobe::accel::Isa;
use englobe::geom::aabb::ROBUST_FAR_SCALE;
use englobe::{Aabb, AccelKind, NoCount, Ray, TriangleBvh, TriangleMesh, Vec3, World};

/// A closed fan: `sides` triangles around the shared vertex `apex`, their far vertices on a
/// circle in the plane z = apex.z (so the apex lies on the top or bottom face of every box), plus
/// a cone below closing it off.
fn fan(apex: Vec3, radius: f32, sides: u32) -> TriangleMesh {
    let mut positions = vec![apex];
    for i in 0..sides {
        let a = std::f32::consts::TAU * i as f32 / sides as f32;
        positions.push(apex + Vec3::new(a.cos(), a.sin(), 0.0) * radius);
    }
    positions.push(apex - Vec3::Z * radius);
    let bottom = sides + 1;
    let mut triangles = Vec::new();
    for i in 0..sides {
        let (a, b) = (1 + i, 1 + (i + 1) % sides);
        triangles.push([0, a, b]);
        triangles.push([b, a, bottom]);
    }
    TriangleMesh::new(positions, triangles).unwrap()
}

/// The fans the tests use: apexes with awkward coordinates near the origin and far from it.
fn fans() -> Vec<TriangleMesh> {
    vec![
        fan(Vec3::new(0.1, 0.7, 0.3), 0.25, 7),
        fan(Vec3::new(-1.3e-3, 2.7e-3, 5.9e-4), 1e-3, 12),
        fan(Vec3::new(148376.0, 1234.0, -223423.0), 3.5, 9),
    ]
}

/// Rays from random points around the fan, aimed exactly at its apex (`t = 1` there).
fn rays_at_apex(mesh: &TriangleMesh, count: usize, seed: u64) -> Vec<Ray> {
    let apex = mesh.positions()[0];
    let reach = mesh.bounds().extent().max_element() * 4.0;
    let mut rng = seeded(seed);
    (0..count)
        .map(|_| {
            let origin = apex + in_cube(&mut rng) * reach;
            Ray::new(origin, apex - origin)
        })
        .filter(|r| r.is_valid())
        .collect()
}

#[test]
fn rays_through_a_shared_vertex_on_box_faces_hit_in_every_structure() {
    for mesh in fans() {
        let rays = rays_at_apex(&mesh, 20_000, 3);
        let brute = World::build(vec![mesh.clone().into()], AccelKind::None).unwrap();
        for isa in Isa::available() {
            let mut fast = TriangleBvh::build(&mesh);
            fast.set_isa(isa).unwrap();
            for ray in &rays {
                let expected = brute.closest_hit(ray, &mut NoCount).map(|h| (h.t, h.prim));
                assert_eq!(
                    fast.closest_hit(ray, &mut NoCount).map(|h| (h.t, h.prim)),
                    expected,
                    "TriangleBvh ({isa}): {ray:?}"
                );
                assert!(fast.any_hit(ray, &mut NoCount), "TriangleBvh ({isa}): any-hit misses {ray:?}");
            }
        }
        for &kind in AccelKind::ALL {
            let world = World::build(vec![mesh.clone().into()], kind).unwrap();
            for ray in &rays {
                let expected = brute.closest_hit(ray, &mut NoCount);
                assert!(expected.is_some(), "brute force misses the apex: {ray:?}");
                let got = world.closest_hit(ray, &mut NoCount);
                assert_eq!(got.map(|h| (h.t, h.prim)), expected.map(|h| (h.t, h.prim)), "{kind}: {ray:?}");
                assert!(world.any_hit(ray, &mut NoCount), "{kind}: any-hit misses {ray:?}");
            }
        }
    }
}

/// Pairs of a ray of `rays` and a triangle it hits whose box the slab test with exit scale
/// `far_scale` rejects: a structure culling with that test would lose that hit, and with it the
/// closest primitive whenever the lost triangle is the one of lowest index among those hit at the
/// apex (ties at equal `t` go to the lowest index).
fn lost_by_the_box_test(mesh: &TriangleMesh, rays: &[Ray], far_scale: f32) -> usize {
    let mut lost = 0;
    for ray in rays {
        let mut hits = 0;
        for (t, tri) in mesh.triangles().iter().enumerate() {
            if mesh.intersect(t as u32, ray).is_some() {
                hits += 1;
                let (enter, exit) =
                    Aabb::from_points(tri.map(|i| mesh.positions()[i as usize])).slab_distances(ray, far_scale);
                lost += usize::from(enter > exit);
            }
        }
        assert!(hits > 0, "{ray:?}");
    }
    lost
}

#[test]
fn the_widened_slab_test_keeps_what_the_plain_one_loses() {
    let (mut robust, mut plain, mut total) = (0, 0, 0);
    for mesh in fans() {
        let rays = rays_at_apex(&mesh, 20_000, 5);
        total += rays.len();
        robust += lost_by_the_box_test(&mesh, &rays, ROBUST_FAR_SCALE);
        plain += lost_by_the_box_test(&mesh, &rays, 1.0);
    }
    eprintln!("{total} rays: the widened test loses {robust} hits, the plain one {plain}");
    assert_eq!(robust, 0, "the widened test loses {robust} hits of {total} rays");
    assert!(plain > 0, "the plain test loses no hit of {total} rays: this test would not catch its removal");
}
