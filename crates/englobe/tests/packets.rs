//! Packet queries ([`TriangleBvh::closest_hit_packet`], [`TriangleBvh::any_hit_packet`], and the
//! same handed over as rows: [`TriangleBvh::closest_hit_ray_packet`]) and the
//! batches that pick them against the single-ray queries (which the other tests check against
//! brute force): the same answer for every ray, bit for bit, in every instruction set, for
//! coherent packets (which take the whole-packet triangle test when their rays share axes) and
//! incoherent ones, partial packets and invalid rays, rays through shared vertices and edges; and
//! a [`World`]'s packets, whose rays go on alone through shapes, instances and planes.

mod common;

use common::load_obj;
use common::rng::{RngExt, cube_direction, in_cube, seeded};
use common::strategies::triangle;
use englobe::accel::wide::Isa;
use englobe::accel::wide::packet_kernels::PACKET;
use englobe::accel::wide::triangle_packet::coherent;
use englobe::{
    AccelKind, Affine3A, Hit, Instance, NoCount, Object, Plane, Ray, RayPacket, Sphere, TriangleBvh, Vec3, WorkCounts,
    World,
};
use proptest::prelude::*;

/// Checks the packet queries and the batches of `bvh` against its single-ray queries on `rays`,
/// in every instruction set; returns the number of rays that hit.
fn check(bvh: &mut TriangleBvh, rays: &[Ray]) -> Result<usize, String> {
    let mut found = 0;
    for isa in Isa::available() {
        bvh.set_isa(isa).map_err(|e| e.to_string())?;
        let single: Vec<Option<Hit>> = rays.iter().map(|r| bvh.closest_hit(r, &mut NoCount)).collect();
        let single_any: Vec<bool> = rays.iter().map(|r| bvh.any_hit(r, &mut NoCount)).collect();
        let (mut hits, mut batch) = (vec![None; rays.len()], vec![None; rays.len()]);
        let (mut any, mut batch_any) = (vec![false; rays.len()], vec![false; rays.len()]);
        bvh.closest_hit_packet(rays, &mut hits, &mut WorkCounts::default()).map_err(|e| e.to_string())?;
        bvh.any_hit_packet(rays, &mut any, &mut NoCount).map_err(|e| e.to_string())?;
        bvh.closest_hits(rays, &mut batch).map_err(|e| e.to_string())?;
        bvh.any_hits(rays, &mut batch_any).map_err(|e| e.to_string())?;
        // The same packets handed over as rows, all lanes traced, then every other lane.
        let (mut rows, mut rows_any) = (vec![None; rays.len()], vec![false; rays.len()]);
        for (k, chunk) in rays.chunks(PACKET).enumerate() {
            let mut packet = RayPacket::default();
            for (lane, r) in chunk.iter().enumerate() {
                packet.set(lane, r.origin(), r.dir(), r.t_min, r.t_max);
            }
            let all = (1u32 << chunk.len()) - 1;
            let got = bvh.closest_hit_ray_packet(&packet, all, &mut WorkCounts::default());
            let got_any = bvh.any_hit_ray_packet(&packet, all, &mut NoCount);
            let half = all & 0x5555;
            let (some, some_any) = (
                bvh.closest_hit_ray_packet(&packet, half, &mut NoCount),
                bvh.any_hit_ray_packet(&packet, half, &mut NoCount),
            );
            for lane in 0..chunk.len() {
                let i = k * PACKET + lane;
                (rows[i], rows_any[i]) = (got.hit(lane), got_any >> lane & 1 != 0);
                let expected = if half >> lane & 1 != 0 { (single[i], single_any[i]) } else { (None, false) };
                if (some.hit(lane), some_any >> lane & 1 != 0) != expected {
                    return Err(format!("{isa}, every other lane, ray {i} {:?}: expected {expected:?}", rays[i]));
                }
            }
        }
        for (i, ray) in rays.iter().enumerate() {
            let expected = (single[i], single_any[i]);
            for (what, got) in
                [("packet", (hits[i], any[i])), ("batch", (batch[i], batch_any[i])), ("rows", (rows[i], rows_any[i]))]
            {
                if got != expected {
                    return Err(format!("{isa}, {what}, ray {i} {ray:?}: single rays {expected:?}, {got:?}"));
                }
            }
        }
        found = single.iter().filter(|h| h.is_some()).count();
    }
    Ok(found)
}

/// The rays of a pinhole camera at `eye` looking at `target`, `n` x `n` pixels, stored in 4 x 4
/// tiles so that sixteen consecutive rays form a square packet.
fn camera(eye: Vec3, target: Vec3, fov: f32, n: usize) -> Vec<Ray> {
    let forward = (target - eye).normalize();
    let right = forward.cross(Vec3::Y).normalize();
    let up = right.cross(forward);
    let half = (fov.to_radians() * 0.5).tan();
    let mut rays = Vec::with_capacity(n * n);
    for ty in (0..n).step_by(4) {
        for tx in (0..n).step_by(4) {
            for y in ty..ty + 4 {
                for x in tx..tx + 4 {
                    let sx = ((x as f32 + 0.5) / n as f32 * 2.0 - 1.0) * half;
                    let sy = ((y as f32 + 0.5) / n as f32 * 2.0 - 1.0) * half;
                    rays.push(Ray::new(eye, forward + right * sx + up * sy));
                }
            }
        }
    }
    rays
}

#[test]
fn camera_and_shadow_packets_on_the_bunny() {
    let mesh = load_obj("scenes/meshes/bunny/stanford-bunny.obj");
    let mut bvh = TriangleBvh::build(&mesh);
    let b = mesh.bounds();
    let eye = b.center() + Vec3::new(0.3, 0.2, 1.0) * b.extent().length();
    let rays = camera(eye, b.center(), 30.0, 64);
    assert!(rays.chunks(PACKET).filter(|p| coherent(p, &b)).count() * 10 > rays.len() / PACKET * 9);
    let hits = check(&mut bvh, &rays).unwrap();
    assert!(hits > rays.len() / 4, "{hits} hits of {}", rays.len());

    // Shadow rays from the hits towards one light, as segments stopping short of it, in the same
    // order: neighbouring points, so mostly coherent packets.
    let light = b.center() + Vec3::new(-0.5, 1.0, 0.4) * b.extent().length();
    let shadows: Vec<Ray> = rays
        .iter()
        .filter_map(|r| bvh.closest_hit(r, &mut NoCount).map(|h| r.at(h.t)))
        .map(|p| {
            let d = light - p;
            Ray::segment(p + d * 1e-4, d, 0.0, 0.999)
        })
        .collect();
    check(&mut bvh, &shadows).unwrap();
    let blocked = shadows.iter().filter(|r| bvh.any_hit(r, &mut NoCount)).count();
    assert!(blocked > 50 && blocked < shadows.len() - 50, "{blocked} of {} shadow rays blocked", shadows.len());

    // The work a packet's rays count (each ray counts the nodes and triangles it is tested
    // against): on coherent rays, about what the rays count alone. A leaf entered by any ray of a
    // packet is tested for every ray that enters its box, so the packets count at least as many
    // triangle tests here, but not many more.
    let (mut single, mut packets) = (WorkCounts::default(), WorkCounts::default());
    let mut out = vec![None; rays.len()];
    for r in &rays {
        bvh.closest_hit(r, &mut single);
    }
    bvh.closest_hit_packet(&rays, &mut out, &mut packets).unwrap();
    assert!(packets.exact_tests >= single.exact_tests, "a packet tests the union of its rays' leaves");
    assert!(packets.exact_tests < 2 * single.exact_tests, "{} against {}", packets.exact_tests, single.exact_tests);
}

#[test]
fn world_packets_answer_as_single_rays_do() {
    let bunny = std::sync::Arc::new(load_obj("scenes/meshes/bunny/stanford-bunny.obj"));
    let b = bunny.bounds();
    let objects: Vec<Object> = vec![
        Object::Mesh(bunny.clone()),
        Instance::new(bunny.clone(), Affine3A::from_translation(Vec3::X * b.extent().x * 1.1)).unwrap().into(),
        Sphere::new(b.center() - Vec3::X * b.extent().x * 0.8, b.extent().y * 0.3).into(),
        Plane::new(Vec3::Y, b.min - Vec3::Y * 1e-3).unwrap().into(),
    ];
    let world = World::build(objects, AccelKind::BvhWide).unwrap();
    let eye = b.center() + Vec3::new(0.2, 0.4, 1.5) * b.extent().length();
    let mut rays = camera(eye, b.center(), 50.0, 48);
    rays[5] = Ray::new(eye, Vec3::ZERO);
    let single: Vec<_> = rays.iter().map(|r| world.closest_hit(r, &mut NoCount)).collect();
    let single_any: Vec<_> = rays.iter().map(|r| world.any_hit(r, &mut NoCount)).collect();
    let (mut hits, mut batch) = (vec![None; rays.len()], vec![None; rays.len()]);
    let (mut any, mut batch_any) = (vec![false; rays.len()], vec![false; rays.len()]);
    world.closest_hit_packet(&rays, &mut hits, &mut WorkCounts::default()).unwrap();
    world.any_hit_packet(&rays, &mut any, &mut NoCount).unwrap();
    world.closest_hits(&rays, &mut batch).unwrap();
    world.any_hits(&rays, &mut batch_any).unwrap();
    assert_eq!(hits, single);
    assert_eq!(batch, single);
    assert_eq!(any, single_any);
    assert_eq!(batch_any, single_any);
    // Every kind of object is seen.
    for object in 0..4 {
        assert!(single.iter().flatten().any(|h| h.object == object), "object {object} never hit");
    }
}

#[test]
fn vertical_packets_through_shared_vertices_and_edges() {
    // A folded grid with integer coordinates; packets of sixteen parallel rays (sharing axes, so
    // the whole-packet triangle test runs) through its vertices and edges, with zero components of
    // both signs: edge functions of exactly zero, which the scalar test must decide.
    let n = 12;
    let tris = common::folded_grid(n);
    let mut bvh = TriangleBvh::from_triangles(&tris);
    let mut rays = Vec::new();
    for d in [Vec3::new(0.0, -0.0, -1.0), Vec3::new(-0.0, 0.0, -1.0), Vec3::new(0.125, 0.25, -1.0)] {
        for i in 0..=2 * n {
            for j in 0..=2 * n {
                rays.push(Ray::new(Vec3::new(i as f32 * 0.5, j as f32 * 0.5, 5.0), d));
            }
        }
    }
    let hits = check(&mut bvh, &rays).unwrap();
    // Watertight: every vertical ray inside the grid's footprint hits.
    assert!(hits >= 2 * (2 * n + 1) * (2 * n + 1), "{hits}");
}

/// Packets from one origin in directions within a narrow cone (coherent) or anywhere, over the
/// whole line or a segment, some invalid, `n` rays in all.
fn packet_rays(seed: u64, n: usize, narrow: bool) -> Vec<Ray> {
    let mut rng = seeded(seed);
    let mut rays = Vec::with_capacity(n);
    while rays.len() < n {
        let origin = in_cube(&mut rng) * 3.0;
        let axis = cube_direction(&mut rng);
        for _ in 0..rng.random_range(1..=PACKET) {
            let d = if narrow { axis + in_cube(&mut rng) * 0.05 } else { cube_direction(&mut rng) };
            let (t0, t1) = [(0.0, f32::INFINITY), (0.5, 3.0), (1.0, 1.0)][rng.random_range(0..3)];
            rays.push(match rng.random_range(0..40) {
                0 => Ray::new(origin, Vec3::ZERO),
                1 => Ray::segment(origin, d, 2.0, 1.0),
                _ => Ray::segment(origin, d, t0, t1),
            });
        }
    }
    rays.truncate(n);
    rays
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(48))]

    #[test]
    fn random_soups_answer_as_single_rays_do(
        tris in prop::collection::vec(triangle(), 1..400),
        seed in any::<u64>(),
        n in 1usize..200,
        narrow in any::<bool>(),
    ) {
        let mut bvh = TriangleBvh::from_triangles(&tris);
        check(&mut bvh, &packet_rays(seed, n, narrow)).map_err(TestCaseError::fail)?;
    }
}
