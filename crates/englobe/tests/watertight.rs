//! Watertightness of the ray/triangle test (Woop, Benthin and Wald 2013, "Watertight Ray/Triangle
//! Intersection"): a ray leaving a point inside a closed mesh must hit it, even where it passes
//! exactly through a shared edge or vertex, near the origin and far from it.
//!
//! The mesh is a finely tessellated latitude/longitude sphere. Testing every triangle for each of
//! a million rays would take minutes, so each ray is tested against the triangles of the cells
//! around the point where it leaves the ideal sphere (and against every triangle of the bands
//! around a pole, where longitudes converge). The polygonal mesh lies within a small fraction of a
//! cell of the ideal sphere, so the triangle the ray really leaves through is always among them:
//! a candidate set too small could only report a false miss, never hide one.

mod common;

use std::sync::Arc;

use common::rng::{Pcg32, RngExt, seeded};
use englobe::accel::Isa;
use englobe::{AccelKind, Affine3A, Instance, NoCount, Object, Ray, TriangleBvh, TriangleMesh, Vec3, World};
use glam::DVec3;
use rayon::prelude::*;

/// A latitude/longitude sphere with its triangles grouped by cell (band, sector).
struct UvSphere {
    mesh: TriangleMesh,
    center: Vec3,
    radius: f32,
    bands: usize,
    sectors: usize,
    /// Triangles of cell `band * sectors + sector`.
    cells: Vec<Vec<u32>>,
}

impl UvSphere {
    /// A sphere whose every vertex lies at `radius * (1 + jitter * u)`, `u` uniform in -1..1
    /// (the two poles are single vertices shared by a whole band).
    fn new(center: Vec3, radius: f32, bands: usize, sectors: usize, jitter: f64) -> Self {
        let c = center.as_dvec3();
        let mut rng = seeded(0x5EED ^ (bands * sectors) as u64);
        let mut point = |band: usize, sector: usize| -> Vec3 {
            let theta = std::f64::consts::PI * band as f64 / bands as f64;
            let phi = -std::f64::consts::PI + std::f64::consts::TAU * sector as f64 / sectors as f64;
            let r = radius as f64 * (1.0 + jitter * (2.0 * rng.random::<f64>() - 1.0));
            (c + DVec3::new(theta.sin() * phi.cos(), theta.sin() * phi.sin(), theta.cos()) * r).as_vec3()
        };
        let mut positions = vec![point(0, 0)];
        for band in 1..bands {
            positions.extend((0..sectors).map(|s| point(band, s)));
        }
        positions.push(point(bands, 0));
        let south = (positions.len() - 1) as u32;
        let ring = |band: usize, sector: usize| (1 + (band - 1) * sectors + sector % sectors) as u32;
        let mut triangles = Vec::new();
        let mut cells = vec![Vec::new(); bands * sectors];
        for band in 0..bands {
            for s in 0..sectors {
                let cell = &mut cells[band * sectors + s];
                let mut push = |t: [u32; 3]| {
                    cell.push(triangles.len() as u32);
                    triangles.push(t);
                };
                if band == 0 {
                    push([0, ring(1, s), ring(1, s + 1)]);
                } else if band == bands - 1 {
                    push([ring(band, s), south, ring(band, s + 1)]);
                } else {
                    let (a, b, c, d) = (ring(band, s), ring(band + 1, s), ring(band + 1, s + 1), ring(band, s + 1));
                    push([a, b, c]);
                    push([a, c, d]);
                }
            }
        }
        let mesh = TriangleMesh::new(positions, triangles).unwrap();
        UvSphere { mesh, center, radius, bands, sectors, cells }
    }

    /// The triangles the ray may leave through: the cells around its exit from the ideal sphere.
    fn candidates(&self, ray: &Ray, out: &mut Vec<u32>) {
        out.clear();
        let o = ray.origin().as_dvec3() - self.center.as_dvec3();
        let d = ray.dir().as_dvec3().normalize();
        let b = o.dot(d);
        let c = o.dot(o) - (self.radius as f64).powi(2);
        let t = -b + (b * b - c).max(0.0).sqrt();
        let q = (o + d * t) / self.radius as f64;
        let theta = q.z.clamp(-1.0, 1.0).acos();
        let phi = q.y.atan2(q.x);
        let band = ((theta / std::f64::consts::PI * self.bands as f64) as usize).min(self.bands - 1);
        let sector = (((phi + std::f64::consts::PI) / std::f64::consts::TAU * self.sectors as f64) as usize)
            .min(self.sectors - 1);
        // Two cells either way: the jittered vertices move the surface off the ideal sphere.
        for bd in band.saturating_sub(2)..=(band + 2).min(self.bands - 1) {
            if bd <= 3 || bd + 4 >= self.bands {
                // Near a pole every sector is close: take the whole band.
                for s in 0..self.sectors {
                    out.extend(&self.cells[bd * self.sectors + s]);
                }
            } else {
                for ds in [self.sectors - 2, self.sectors - 1, 0, 1, 2] {
                    out.extend(&self.cells[bd * self.sectors + (sector + ds) % self.sectors]);
                }
            }
        }
    }

    fn hits(&self, ray: &Ray, scratch: &mut Vec<u32>) -> bool {
        self.candidates(ray, scratch);
        scratch.iter().any(|&t| self.mesh.intersect(t, ray).is_some())
    }
}

/// Uniform in the unit ball, away from its centre (so that it can be normalised).
fn in_ball(rng: &mut Pcg32) -> DVec3 {
    loop {
        let p = DVec3::new(rng.random(), rng.random(), rng.random()) * 2.0 - 1.0;
        if p.length_squared() <= 1.0 && p.length_squared() > 1e-6 {
            return p;
        }
    }
}

fn random_rays_from_inside(sphere: &UvSphere, count: usize, seed: u64) -> usize {
    let mut scratch = Vec::new();
    random_rays(sphere, count, seed).filter(|ray| !sphere.hits(ray, &mut scratch)).count()
}

/// `count` rays from uniform points in the inner 90 % of the ball in uniform directions.
fn random_rays(sphere: &UvSphere, count: usize, seed: u64) -> impl Iterator<Item = Ray> + '_ {
    let mut rng = seeded(seed);
    (0..count).map(move |_| {
        let origin = (sphere.center.as_dvec3() + in_ball(&mut rng) * (0.9 * sphere.radius as f64)).as_vec3();
        Ray::new(origin, in_ball(&mut rng).normalize().as_vec3())
    })
}

/// Rays aimed exactly at every vertex and every edge midpoint, from the centre and from an
/// off-centre point inside.
fn rays_at_vertices_and_edges(sphere: &UvSphere) -> Vec<Ray> {
    let m = &sphere.mesh;
    let mut targets: Vec<Vec3> = m.positions().to_vec();
    for t in m.triangles() {
        for k in 0..3 {
            let (a, b) = (m.positions()[t[k] as usize], m.positions()[t[(k + 1) % 3] as usize]);
            targets.push((a + b) * 0.5);
        }
    }
    let origins = [sphere.center, sphere.center + Vec3::new(0.31, -0.22, 0.47) * sphere.radius];
    origins.iter().flat_map(|&o| targets.iter().map(move |&target| Ray::new(o, target - o))).collect()
}

/// How many of the rays aimed at vertices and edge midpoints miss, and how many there are.
fn misses_at_vertices_and_edges(sphere: &UvSphere) -> (usize, usize) {
    let rays = rays_at_vertices_and_edges(sphere);
    let mut scratch = Vec::new();
    (rays.iter().filter(|ray| !sphere.hits(ray, &mut scratch)).count(), rays.len())
}

const FAR: Vec3 = Vec3::new(148376.0, 1234.0, -223423.0);

/// Relative jitter of the vertices' radii: a fifth of a band's width on the finest sphere, so the
/// ideal sphere still tells which cells a ray leaves through, while no two neighbouring triangles
/// are symmetric.
const JITTER: f64 = 0.005;

#[test]
fn a_million_rays_from_inside_a_sphere_at_the_origin_never_miss() {
    let sphere = UvSphere::new(Vec3::ZERO, 1.0, 128, 256, JITTER);
    assert_eq!(sphere.mesh.len(), 2 * 128 * 256 - 2 * 256);
    assert_eq!(random_rays_from_inside(&sphere, 1_000_000, 0x9E37_79B9_7F4A_7C15), 0);
    let (misses, rays) = misses_at_vertices_and_edges(&sphere);
    assert!(rays > 2 * 190_000, "{rays}");
    assert_eq!(misses, 0, "{misses} of {rays} rays aimed at vertices and edge midpoints missed");
}

#[test]
fn a_million_rays_from_inside_a_sphere_far_from_the_origin_never_miss() {
    let sphere = UvSphere::new(FAR, 100.0, 128, 256, JITTER);
    assert_eq!(random_rays_from_inside(&sphere, 1_000_000, 0xD1B5_4A32_D192_ED03), 0);
    let (misses, rays) = misses_at_vertices_and_edges(&sphere);
    assert_eq!(misses, 0, "{misses} of {rays} rays aimed at vertices and edge midpoints missed");
}

#[test]
fn the_candidate_cells_do_hold_the_hit() {
    // Guard the test's own shortcut: on a coarser sphere, every triangle a ray hits is among its
    // candidates (so the tests above could only over-report misses).
    let sphere = UvSphere::new(FAR, 100.0, 24, 48, JITTER);
    let mut rng = seeded(7);
    let mut scratch = Vec::new();
    for _ in 0..20_000 {
        let origin = (sphere.center.as_dvec3() + in_ball(&mut rng) * 90.0).as_vec3();
        let ray = Ray::new(origin, in_ball(&mut rng).normalize().as_vec3());
        sphere.candidates(&ray, &mut scratch);
        for t in 0..sphere.mesh.len() as u32 {
            if sphere.mesh.intersect(t, &ray).is_some() {
                assert!(scratch.contains(&t), "triangle {t} is hit but not a candidate");
            }
        }
    }
}

#[test]
fn rays_from_inside_an_instanced_sphere_never_miss() {
    // The same property through the world and an instance: the ray is moved into mesh space.
    let sphere = UvSphere::new(Vec3::ZERO, 1.0, 16, 32, JITTER);
    let mesh = Arc::new(sphere.mesh);
    let place = Affine3A::from_scale_rotation_translation(Vec3::splat(100.0), glam::Quat::from_rotation_z(0.4), FAR);
    let world = World::build(vec![Instance::new(mesh, place).unwrap().into()], AccelKind::None).unwrap();
    let mut rng = seeded(11);
    for _ in 0..20_000 {
        let origin = (FAR.as_dvec3() + in_ball(&mut rng) * 90.0).as_vec3();
        let ray = Ray::new(origin, in_ball(&mut rng).normalize().as_vec3());
        assert!(world.closest_hit(&ray, &mut NoCount).is_some(), "{ray:?}");
        assert!(world.any_hit(&ray, &mut NoCount));
    }
}

#[test]
fn every_structure_finds_the_jittered_sphere_from_inside() {
    // The same rays through the world, with every structure: a structure must not lose through
    // its boxes what the triangle test finds. A million random rays from inside and the rays at
    // every vertex and edge midpoint, at the origin and far from it; `TriangleBvh` in every
    // instruction set too. The seed's two BVHs, whose
    // traversal visits thousands of nodes per ray on a mesh this size, take every 100th ray.
    for (center, radius, seed) in [(Vec3::ZERO, 1.0, 0x243F_6A88_85A3_08D3), (FAR, 100.0, 0x1319_8A2E_0370_7344)] {
        let sphere = UvSphere::new(center, radius, 128, 256, JITTER);
        let mut rays: Vec<Ray> = random_rays(&sphere, 1_000_000, seed).collect();
        rays.extend(rays_at_vertices_and_edges(&sphere));
        for isa in Isa::available() {
            // The triangle-mesh fast path, in every instruction set this processor has.
            let mut fast = TriangleBvh::build(&sphere.mesh);
            fast.set_isa(isa).unwrap();
            let misses = rays.par_iter().filter(|ray| fast.closest_hit(ray, &mut NoCount).is_none()).count();
            assert_eq!(misses, 0, "TriangleBvh ({isa}) at {center}: {misses} of {} rays miss", rays.len());
            let any_misses = rays.par_iter().filter(|ray| !fast.any_hit(ray, &mut NoCount)).count();
            assert_eq!(any_misses, 0, "TriangleBvh ({isa}) at {center}: {any_misses} any-hit misses");
        }
        let mesh = Arc::new(sphere.mesh);
        for &kind in AccelKind::ALL.iter().filter(|&&k| k != AccelKind::None) {
            let world = World::build(vec![Object::Mesh(mesh.clone())], kind).unwrap();
            let step = if matches!(kind, AccelKind::BvhSeed | AccelKind::BvhSeedOrdered) { 100 } else { 1 };
            let rays: Vec<&Ray> = rays.iter().step_by(step).collect();
            let misses = rays.par_iter().filter(|ray| world.closest_hit(ray, &mut NoCount).is_none()).count();
            assert_eq!(misses, 0, "{kind} at {center}: {misses} of {} rays miss", rays.len());
            let any_misses = rays.par_iter().filter(|ray| !world.any_hit(ray, &mut NoCount)).count();
            assert_eq!(any_misses, 0, "{kind} at {center}: {any_misses} of {} any-hit queries miss", rays.len());
        }
    }
}
