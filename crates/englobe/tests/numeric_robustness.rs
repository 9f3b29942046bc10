//! Numeric robustness of every structure, through `World`: the same scene at every scale `f32`
//! can hold gives the same picture, and invalid rays (NaN, infinities, zero directions, empty
//! intervals) miss at once, without panicking and without traversing anything.

use std::sync::Arc;

use englobe::{AaBox, AccelKind, NoCount, Object, Plane, Ray, Sphere, Triangle, TriangleMesh, Vec3, WorkCounts, World};

/// A small scene with every kind of shape: spheres, a box, loose triangles, a mesh, an instance
/// and a plane, all scaled by `s`.
fn scene(s: f32) -> Vec<Object> {
    let v = |x: f32, y: f32, z: f32| Vec3::new(x, y, z) * s;
    // A tetrahedron mesh, placed as is and once more through an instance.
    let tetra = Arc::new(
        TriangleMesh::new(
            vec![v(0.0, 0.0, 0.0), v(1.1, 0.1, 0.2), v(0.3, 1.2, -0.1), v(0.4, 0.35, 1.05)],
            vec![[0, 2, 1], [0, 1, 3], [1, 2, 3], [0, 3, 2]],
        )
        .unwrap(),
    );
    let shifted = englobe::Affine3A::from_translation(v(-2.3, 0.7, 0.4));
    vec![
        Sphere::new(v(0.13, 0.21, 0.37), 0.83 * s).into(),
        Sphere::new(v(-1.71, -0.93, 1.13), 0.41 * s).into(),
        AaBox::new(v(1.07, -1.29, 0.31), v(1.93, -0.37, 1.41)).into(),
        Triangle::new(v(-0.9, 1.1, 2.0), v(0.7, 1.9, 2.3), v(-0.2, 2.4, 1.7)).into(),
        Object::Mesh(tetra.clone()),
        Object::Instance(englobe::Instance::new(tetra, shifted).unwrap()),
        Plane::new(Vec3::new(0.03, 1.0, -0.02), v(0.0, -1.9, 0.0)).unwrap().into(),
    ]
}

/// What the camera sees: for each of 64 x 64 rays from a point scaled by `s`, the object hit.
fn picture(world: &World, s: f32) -> Vec<Option<u32>> {
    let eye = Vec3::new(0.37, 0.91, -6.3) * s;
    let mut hits = Vec::with_capacity(64 * 64);
    for j in 0..64 {
        for i in 0..64 {
            let dir = Vec3::new((i as f32 + 0.5) / 64.0 - 0.5, 0.5 - (j as f32 + 0.5) / 64.0, 1.0).normalize();
            hits.push(world.closest_hit(&Ray::new(eye, dir), &mut NoCount).map(|h| h.object));
        }
    }
    hits
}

#[test]
fn every_scale_f32_can_hold_gives_the_same_picture() {
    let reference = picture(&World::build(scene(1.0), AccelKind::None).unwrap(), 1.0);
    let seen: std::collections::HashSet<_> = reference.iter().collect();
    assert!(seen.len() >= 7, "the picture shows most objects and the background: {seen:?}");
    for s in [1e-30f32, 1e-10, 1.0, 1e10, 1e30] {
        for &kind in AccelKind::ALL {
            let world = World::build(scene(s), kind).unwrap();
            let got = picture(&world, s);
            let differ = got.iter().zip(&reference).filter(|(a, b)| a != b).count();
            assert_eq!(differ, 0, "scale {s:e}, {kind}: {differ} of 4096 rays see something else");
        }
    }
}

#[test]
fn distances_scale_with_the_scene() {
    let ray = |s: f32| Ray::new(Vec3::new(0.13, 0.21, -5.0) * s, Vec3::Z);
    let t1 = World::build(scene(1.0), AccelKind::None).unwrap().closest_hit(&ray(1.0), &mut NoCount).unwrap().t;
    for s in [1e-30f32, 1e-10, 1e10, 1e30] {
        let w = World::build(scene(s), AccelKind::None).unwrap();
        let t = w.closest_hit(&ray(s), &mut NoCount).unwrap().t;
        assert!((t / s - t1).abs() <= 1e-5 * t1, "scale {s:e}: t = {t}, expected {}", t1 * s);
    }
}

/// Rays no structure may hit anything with.
fn invalid_rays() -> Vec<Ray> {
    let (nan, inf) = (f32::NAN, f32::INFINITY);
    let o = Vec3::new(0.1, 0.2, -5.0);
    let d = Vec3::new(0.01, 0.02, 1.0);
    let mut rays = vec![
        Ray::new(Vec3::new(nan, 0.0, -5.0), d),
        Ray::new(Vec3::new(0.0, inf, -5.0), d),
        Ray::new(Vec3::new(0.0, 0.0, -inf), d),
        Ray::new(o, Vec3::new(nan, 0.0, 1.0)),
        Ray::new(o, Vec3::new(0.0, inf, 1.0)),
        Ray::new(o, Vec3::new(-inf, -inf, -inf)),
        Ray::new(o, Vec3::ZERO),
        Ray::new(o, Vec3::new(-0.0, 0.0, -0.0)),
        Ray::segment(o, d, nan, 10.0),
        Ray::segment(o, d, 0.0, nan),
        Ray::segment(o, d, 5.0, 4.0),
        Ray::segment(o, d, inf, inf),
        Ray::segment(o, d, -inf, -inf),
    ];
    rays.extend(rays.clone().iter().map(|r| Ray::segment(Vec3::splat(nan), r.dir(), r.t_min, r.t_max)));
    rays
}

#[test]
fn invalid_rays_miss_at_once_in_every_structure() {
    let objects = scene(1.0);
    let valid: Vec<Ray> = (0..100_000)
        .map(|i| {
            let a = i as f32 * 0.618_034;
            Ray::new(Vec3::new(0.37, 0.91, -6.3), Vec3::new(a.sin() * 0.4, a.cos() * 0.4, 1.0))
        })
        .collect();
    let invalid = invalid_rays();
    for &kind in AccelKind::ALL {
        let world = World::build(objects.clone(), kind).unwrap();
        let mut valid_work = WorkCounts::default();
        for r in &valid {
            world.closest_hit(r, &mut valid_work);
        }
        let mut invalid_work = WorkCounts::default();
        for i in 0..100_000 {
            let r = &invalid[i % invalid.len()];
            assert!(world.closest_hit(r, &mut invalid_work).is_none(), "{kind}: {r:?} hit something");
            assert!(!world.any_hit(r, &mut invalid_work), "{kind}: {r:?} is occluded");
        }
        // Invalid rays are turned away before any test: far below the 2.5x of valid rays' work
        // that would still be acceptable.
        assert_eq!(invalid_work, WorkCounts::default(), "{kind}: invalid rays did work");
        assert!(valid_work.exact_tests > 0);
    }
}

#[test]
fn tiny_and_signed_zero_components_give_the_same_hits_as_plain_ones() {
    // Directions with components of 1e-40 (subnormal), -0.0 or 0.0 are valid and must find the
    // same objects as the same directions with those components set to zero.
    let objects = scene(1.0);
    for &kind in AccelKind::ALL {
        let world = World::build(objects.clone(), kind).unwrap();
        for (o, d) in [
            (Vec3::new(0.13, 0.21, -5.0), Vec3::Z),
            (Vec3::new(1.5, -0.8, -5.0), Vec3::Z),
            (Vec3::new(-5.0, 1.8, 2.0), Vec3::X),
            (Vec3::new(0.4, 6.0, 0.5), -Vec3::Y),
        ] {
            let plain = world.closest_hit(&Ray::new(o, d), &mut NoCount).map(|h| (h.object, h.t));
            for tweak in [1e-40f32, -1e-40, 0.0, -0.0] {
                let mut d2 = d;
                for axis in 0..3 {
                    if d2[axis] == 0.0 {
                        d2[axis] = tweak;
                    }
                }
                let got = world.closest_hit(&Ray::new(o, d2), &mut NoCount).map(|h| (h.object, h.t));
                assert_eq!(got, plain, "{kind}: direction {d2:?}");
                assert!(got.is_none_or(|(_, t)| t.is_finite()));
            }
        }
    }
}
