//! The ray sets match their definitions: counts, determinism, the primary camera framing the
//! bounding sphere, random rays inside the box, bounce rays leaving their hits on the side the
//! primary ray came from.

use std::path::Path;

use englobe::Vec3;
use englobe_bench::adapters::englobe::{EnglobeLibrary, EnglobeStructure};
use englobe_bench::rays::{self, FramingCamera, RayParams, primary_pixel};
use englobe_bench::run::generate_rays;
use englobe_bench::{BenchScene, Library, RayResult};
use englobe_scene::shared_data::shared_meshes_or_panic;

fn bunny() -> BenchScene {
    let meshes = shared_meshes_or_panic(Path::new(env!("CARGO_MANIFEST_DIR")));
    BenchScene::load("bunny", &meshes.join("bunny/stanford-bunny.obj"), None).unwrap()
}

const PARAMS: RayParams = RayParams { resolution: 64, count: 3000, seed: 11 };

#[test]
fn sets_are_deterministic_and_sized() {
    let scene = bunny();
    let a = generate_rays(&scene, PARAMS, 2).unwrap();
    let b = generate_rays(&scene, PARAMS, 1).unwrap();
    assert_eq!((a.primary.len(), a.random.len(), a.bounce.len()), (64 * 64, 3000, 3000));
    assert_eq!(a.primary, b.primary);
    assert_eq!(a.random, b.random);
    assert_eq!(a.bounce, b.bounce);
    let c = generate_rays(&scene, RayParams { seed: 12, ..PARAMS }, 2).unwrap();
    assert_eq!(a.primary, c.primary, "the camera does not depend on the seed");
    assert_ne!(a.random, c.random);
    assert_ne!(a.bounce, c.bounce);
    assert!(a.primary_hit_fraction > 0.1 && a.primary_hit_fraction < 0.9, "{}", a.primary_hit_fraction);
}

#[test]
fn primary_rays_frame_the_bounding_sphere() {
    let scene = bunny();
    let (centre, radius) = scene.bounding_sphere();
    let size = 64;
    let primary = rays::primary_rays(&scene, size);
    let camera = FramingCamera::framing(centre, radius);
    let (mut inside, mut outside) = (0, 0);
    for (i, ray) in primary.iter().enumerate() {
        assert_eq!(ray.origin, camera.eye);
        assert!((ray.dir.length() - 1.0).abs() < 1e-6);
        assert_eq!((ray.t_min, ray.t_max), (0.0, f32::INFINITY));
        // Where the pixel centre lies relative to the circle inscribed in the image.
        let (x, y) = primary_pixel(i, size);
        let px = 2.0 * (x as f32 + 0.5) / size as f32 - 1.0;
        let py = 2.0 * (y as f32 + 0.5) / size as f32 - 1.0;
        let rho = (px * px + py * py).sqrt();
        // Closest approach of the ray to the sphere's centre.
        let to_centre = centre - ray.origin;
        let miss_distance = (to_centre - ray.dir * to_centre.dot(ray.dir)).length();
        if rho < 0.97 {
            assert!(miss_distance < radius, "pixel ({x}, {y}) is inside the disc but misses the sphere");
            inside += 1;
        } else if rho > 1.03 {
            assert!(miss_distance > radius, "pixel ({x}, {y}) is outside the disc but hits the sphere");
            outside += 1;
        }
    }
    assert!(inside > 2500 && outside > 500, "{inside} {outside}");
    // The centre of the image looks at the centre of the sphere, +y is up and +x is right.
    let middle = camera.ray(size / 2, size / 2, size);
    assert!((middle.dir - Vec3::NEG_Z).length() < 0.05);
    assert!(camera.ray(0, 0, size).dir.y > 0.0 && camera.ray(0, 0, size).dir.x < 0.0);
}

#[test]
fn random_rays_start_in_the_box_and_point_everywhere() {
    let scene = bunny();
    let b = scene.bounds();
    let random = rays::random_rays(&scene, 20_000, 5);
    let mut mean = Vec3::ZERO;
    for r in &random {
        assert!(b.contains_point(r.origin), "{:?}", r.origin);
        assert!((r.dir.length() - 1.0).abs() < 1e-6);
        mean += r.dir;
    }
    mean /= random.len() as f32;
    assert!(mean.length() < 0.03, "{mean}");
}

#[test]
fn bounce_rays_leave_their_hits_on_the_incoming_side() {
    let scene = bunny();
    let sets = generate_rays(&scene, PARAMS, 2).unwrap();
    let englobe = EnglobeLibrary::build(&scene, EnglobeStructure::best()).unwrap();
    let mut hits = vec![RayResult::MISS; sets.primary.len()];
    englobe.closest_hits(&sets.primary, &mut hits);
    let hit_rays: Vec<usize> = (0..hits.len()).filter(|&i| hits[i].is_hit()).collect();
    let offset = rays::bounce_offset(&scene);
    for (k, bounce) in sets.bounce.iter().enumerate() {
        let i = hit_rays[k % hit_rays.len()];
        let (primary, hit) = (&sets.primary[i], hits[i]);
        let n = rays::facing_normal(&scene, hit.prim, primary.dir);
        assert!(n.dot(primary.dir) < 0.0, "the normal faces the incoming ray");
        let p = primary.at(hit.t);
        let lift = bounce.origin - p;
        assert!((lift.dot(n) - offset).abs() < 1e-3 * offset, "ray {k} leaves {} off the surface", lift.dot(n));
        assert!((lift - n * offset).length() < 1e-3 * offset);
        assert!(bounce.dir.dot(n) > 0.0, "ray {k} goes back into the surface");
        assert!((bounce.dir.length() - 1.0).abs() < 1e-6);
        // The hit point lies on the hit triangle's plane.
        let v0 = scene.mesh.triangle(hit.prim).vertices[0];
        assert!((p - v0).dot(n).abs() < 1e-5 * (1.0 + hit.t), "{}", (p - v0).dot(n));
    }
}
