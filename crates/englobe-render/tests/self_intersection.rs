//! Secondary rays never hit the surface they leave (pbrt's `Triangle.Reintersect` test, for
//! triangles, spheres and planes, at coordinates over many orders of magnitude), and shadow rays
//! toward a light just above a coplanar neighbour are not falsely occluded.

use englobe::{AccelKind, Intersect, NoCount, Object, Plane, Ray, Sphere, Triangle, Vec3, World};
use englobe_render::optics::offset_ray_origin;
use englobe_render::sampling::cosine_hemisphere;
use rand::{RngExt, SeedableRng};
use rand_pcg::Pcg32;

/// A random unit vector.
fn unit(rng: &mut Pcg32) -> Vec3 {
    loop {
        let v = Vec3::new(rng.random_range(-1.0..1.0), rng.random_range(-1.0..1.0), rng.random_range(-1.0..1.0));
        if v.length_squared() > 1e-4 && v.length_squared() <= 1.0 {
            return v.normalize();
        }
    }
}

/// Hits `shape` at `target` from `from` and checks that 1000 rays leaving the hit point on the
/// side the first ray came from, each from the offset origin, never hit it again.
fn check_reintersection(shape: &Object, from: Vec3, target: Vec3, rng: &mut Pcg32) -> Result<(), String> {
    let world = World::build(vec![shape.clone()], AccelKind::None).unwrap();
    let ray = Ray::new(from, target - from);
    let Some(hit) = world.closest_hit(&ray, &mut NoCount) else { return Ok(()) };
    let p = world.hit_point(&ray, &hit);
    let g = world.geometric_normal(&hit, p);
    let n = if ray.dir().dot(g) < 0.0 { g } else { -g };
    let origin = offset_ray_origin(p, n);
    for _ in 0..1000 {
        let dir = cosine_hemisphere(n, rng.random(), rng.random());
        if dir.dot(n) <= 0.0 {
            continue;
        }
        let leaving = Ray::new(origin, dir);
        if let Some(again) = world.closest_hit(&leaving, &mut NoCount) {
            return Err(format!("ray {leaving:?} leaving {p} re-hit its surface at t = {}", again.t));
        }
    }
    Ok(())
}

#[test]
fn rays_leaving_a_triangle_never_hit_it_again_at_any_magnitude() {
    let mut rng = Pcg32::seed_from_u64(7);
    for exponent in -4..=7 {
        let magnitude = 10f32.powi(exponent);
        for _ in 0..20 {
            // A triangle far from the origin (relative to its size) and of random shape.
            let centre = unit(&mut rng) * magnitude * rng.random_range(0.1f32..10.0);
            let size = magnitude * rng.random_range(0.001f32..1.0);
            let v = [0, 1, 2].map(|_| centre + unit(&mut rng) * size);
            let tri = Triangle::new(v[0], v[1], v[2]);
            if !(tri.double_area() > size * size * 1e-3) {
                continue;
            }
            let (b1, b2) = (rng.random::<f32>(), rng.random::<f32>());
            let (b1, b2) = if b1 + b2 > 1.0 { (1.0 - b1, 1.0 - b2) } else { (b1, b2) };
            let target = v[0] + (v[1] - v[0]) * b1 + (v[2] - v[0]) * b2;
            let from = target + unit(&mut rng) * size * rng.random_range(0.5f32..4.0);
            check_reintersection(&tri.into(), from, target, &mut rng)
                .unwrap_or_else(|e| panic!("magnitude 1e{exponent}: {e}"));
        }
    }
}

#[test]
fn rays_leaving_a_sphere_or_a_plane_never_hit_it_again_at_any_magnitude() {
    let mut rng = Pcg32::seed_from_u64(11);
    for exponent in -4..=7 {
        let magnitude = 10f32.powi(exponent);
        for _ in 0..20 {
            let centre = unit(&mut rng) * magnitude * rng.random_range(0.1f32..10.0);
            let radius = magnitude * rng.random_range(0.001f32..1.0);
            let sphere = Sphere::new(centre, radius);
            let outward = unit(&mut rng);
            let target = centre + outward * radius;
            // From outside: rays leaving a convex surface outward can never meet it again.
            let from = target + (outward * rng.random_range(0.5f32..4.0) + unit(&mut rng) * 0.4) * radius;
            check_reintersection(&sphere.into(), from, target, &mut rng)
                .unwrap_or_else(|e| panic!("sphere, magnitude 1e{exponent}: {e}"));

            let normal = unit(&mut rng);
            let plane = Plane::new(normal, centre).unwrap();
            let along = normal.cross(unit(&mut rng)).normalize_or_zero() * radius;
            let from = centre + along + unit(&mut rng) * radius * rng.random_range(0.5f32..4.0);
            check_reintersection(&plane.into(), from, centre + along, &mut rng)
                .unwrap_or_else(|e| panic!("plane, magnitude 1e{exponent}: {e}"));
        }
    }
}

#[test]
fn a_light_just_above_a_coplanar_neighbour_is_not_occluded() {
    // Two triangles of one plane sharing an edge; a point on the first; a light just above the
    // second, barely above the plane. The shadow ray grazes the neighbour but never crosses it.
    for base in [Vec3::ZERO, Vec3::new(148376.0, 1234.0, -223423.0), Vec3::new(-3.5e6, 2.0e5, 1.0e6)] {
        let s = 1.0 + base.abs().max_element() * 1e-6;
        let a = Triangle::new(base, base + Vec3::new(s, 0.0, 0.0), base + Vec3::new(0.0, 0.0, s));
        let b =
            Triangle::new(base + Vec3::new(s, 0.0, 0.0), base + Vec3::new(s, 0.0, s), base + Vec3::new(0.0, 0.0, s));
        let world = World::build(vec![a.into(), b.into()], AccelKind::None).unwrap();
        let p = base + Vec3::new(0.2, 0.0, 0.2) * s;
        let n = a.normal(p, &englobe::PrimHit::at(0.0));
        let n = if n.y < 0.0 { -n } else { n };
        let origin = offset_ray_origin(p, n);
        for height in [1e-2f32, 1e-3, 1e-4] {
            let light = base + Vec3::new(0.8 * s, height * s, 0.9 * s);
            let shadow = Ray::segment(origin, light - origin, 0.0, 1.0 - 1e-4);
            assert!(!world.any_hit(&shadow, &mut NoCount), "base {base}, light height {height}: falsely occluded");
        }
    }
}
