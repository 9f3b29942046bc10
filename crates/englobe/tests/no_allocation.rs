//! Queries of the wide BVHs allocate nothing: a counting global allocator watches thousands of
//! closest-hit and any-hit queries (with counting off, the zero-sized `NoCount`, and on). Trees
//! deeper than the inline stack grow a per-thread buffer on their first query, and never again;
//! so do the triangle queries that meet more lanes the SIMD test leaves undecided than their
//! inline list holds. Packet queries too, those whose rays are asked again alone included.
//! One test per binary, so that no other test's allocations are counted.

use englobe::accel::bvh::layout::{BuildKind, BuildNode, BuildTree};
use englobe::accel::wide::packet_kernels::PACKET;
use englobe::accel::wide::traverse::INLINE_DEPTH;
use englobe::{Aabb, Accel, Hit, NoCount, PrimHit, Ray, RayPacket, TriangleBvh, Vec3, WideBvh, WorkCounts};

#[path = "common/counting_alloc.rs"]
mod counting_alloc;

use counting_alloc::allocations_during;

#[global_allocator]
static GLOBAL: counting_alloc::Counting = counting_alloc::Counting;

#[test]
fn queries_never_allocate() {
    // A grid of small triangles, and rays across it.
    let mut tris = Vec::new();
    for i in 0..60 {
        for j in 0..60 {
            let o = Vec3::new(i as f32, j as f32, ((i * 7 + j * 3) % 5) as f32);
            tris.push([o, o + Vec3::X, o + Vec3::Y]);
        }
    }
    let rays: Vec<Ray> = (0..5000)
        .map(|k| {
            let f = k as f32;
            Ray::new(
                Vec3::new((f * 0.37) % 60.0, (f * 0.61) % 60.0, 10.0),
                Vec3::new((f * 0.1).sin(), (f * 0.2).cos(), -1.0),
            )
        })
        .collect();
    let tri_bvh = TriangleBvh::from_triangles(&tris);
    let boxes: Vec<Aabb> = tris.iter().map(|t| Aabb::from_points(*t)).collect();
    let wide = WideBvh::build(&boxes);
    let test = |i: u32, r: &Ray| boxes[i as usize].intersect(r).map(|(t, _)| PrimHit::at(t));

    let mut hits = 0;
    let n = allocations_during(|| {
        for r in &rays {
            hits += tri_bvh.closest_hit(r, &mut NoCount).is_some() as usize;
            hits += tri_bvh.any_hit(r, &mut NoCount) as usize;
            hits += tri_bvh.closest_hit(r, &mut WorkCounts::default()).is_some() as usize;
            hits += wide.closest_hit(r, &mut NoCount, test).is_some() as usize;
            hits += wide.any_hit(r, &mut NoCount, |i, r| test(i, r).is_some()) as usize;
        }
    });
    assert_eq!(n, 0, "{n} allocations in {} queries", 5 * rays.len());
    assert!(hits > rays.len(), "{hits}");

    // A tree deeper than the inline stack (a chain: node k holds box k and node k + 1): one
    // buffer per thread, grown on the first query.
    let n = 600u32;
    let boxes: Vec<Aabb> =
        (0..n).map(|i| Aabb::new(Vec3::new(i as f32, 0.0, 0.0), Vec3::new(i as f32 + 0.5, 1.0, 1.0))).collect();
    let mut nodes: Vec<BuildNode> = (0..n as usize)
        .map(|i| BuildNode { bounds: boxes[i], kind: BuildKind::Leaf { first: i as u32, count: 1 } })
        .collect();
    for i in 0..n - 1 {
        let bounds = Aabb::new(Vec3::new(i as f32, 0.0, 0.0), Vec3::new(n as f32, 1.0, 1.0));
        let next = if i + 1 == n - 1 { n - 1 } else { n + i + 1 };
        nodes.push(BuildNode { bounds, kind: BuildKind::Interior { children: [i, next], count: n - i } });
    }
    let deep = WideBvh::from_bvh(&BuildTree { nodes, prims: (0..n).collect(), root: n }.into_bvh());
    assert!(deep.depth() as usize > INLINE_DEPTH, "depth {}", deep.depth());
    let test = |i: u32, r: &Ray| boxes[i as usize].intersect(r).map(|(t, _)| PrimHit::at(t));
    let ray = Ray::new(Vec3::new(1000.0, 0.5, 0.5), -Vec3::X);
    assert_eq!(deep.closest_hit(&ray, &mut NoCount, test).map(|h| h.prim), Some(n - 1));
    let allocated = allocations_during(|| {
        for _ in 0..100 {
            deep.closest_hit(&ray, &mut NoCount, test);
            deep.any_hit(&ray, &mut NoCount, |i, r| test(i, r).is_some());
        }
    });
    assert_eq!(allocated, 0, "{allocated} allocations on a tree of depth {}", deep.depth());

    // Forty triangles around a vertex that the rays go through: every lane undecided, more than
    // the inline list holds, so the queries walk twice with the thread's longer list.
    let fan: Vec<[Vec3; 3]> = (0..40)
        .map(|k| {
            let at = |i: usize| {
                let a = i as f32 * std::f32::consts::TAU / 40.0;
                Vec3::new(a.cos(), a.sin(), 0.0)
            };
            [Vec3::ZERO, at(k), at(k + 1)]
        })
        .collect();
    let fan_bvh = TriangleBvh::from_triangles(&fan);
    // (A filter that refuses every hit keeps the any-hit query from stopping at the first list.)
    let down = Ray::new(Vec3::new(0.0, 0.0, 1.0), -Vec3::Z);
    let refuse = |_: &Hit| false;
    assert!(fan_bvh.closest_hit(&down, &mut NoCount).is_some());
    assert!(!fan_bvh.any_hit_filtered(&down, &mut NoCount, refuse));
    let allocated = allocations_during(|| {
        for _ in 0..100 {
            assert!(fan_bvh.closest_hit(&down, &mut NoCount).is_some());
            assert!(!fan_bvh.any_hit_filtered(&down, &mut NoCount, refuse));
        }
    });
    assert_eq!(allocated, 0, "{allocated} allocations through a shared vertex");

    // Packets: the rays above in rows of sixteen; sixteen rays through the fan's vertex (more
    // undecided pairs than a packet notes: each ray asked again alone); and a packet whose rays
    // do not share the watertight test's axes (asked again ray by ray with AVX-512).
    let rows: Vec<RayPacket> = rays
        .chunks(PACKET)
        .map(|chunk| {
            let mut rows = RayPacket::default();
            for (lane, r) in chunk.iter().enumerate() {
                rows.set(lane, r.origin(), r.dir(), r.t_min, r.t_max);
            }
            rows
        })
        .collect();
    let (mut through_vertex, mut mixed) = (RayPacket::default(), RayPacket::default());
    for lane in 0..PACKET {
        let origin = Vec3::new(0.01 * lane as f32, 0.0, 1.0);
        through_vertex.set(lane, origin, -origin, 0.0, f32::INFINITY);
        let d = if lane % 2 == 0 { Vec3::new(0.3, 0.2, -1.0) } else { Vec3::new(1.0, 0.2, -0.3) };
        mixed.set(lane, Vec3::new(30.0, 30.0, 10.0), d, 0.0, f32::INFINITY);
    }
    let all = u32::MAX >> (32 - PACKET);
    let mut hits = 0;
    let allocated = allocations_during(|| {
        for _ in 0..10 {
            for p in rows.iter().chain([&mixed]) {
                hits += tri_bvh.closest_hit_ray_packet(p, all, &mut NoCount).mask().count_ones();
                hits += tri_bvh.any_hit_ray_packet(p, all, &mut WorkCounts::default()).count_ones();
            }
            assert_eq!(fan_bvh.closest_hit_ray_packet(&through_vertex, all, &mut NoCount).mask(), all);
            assert_eq!(fan_bvh.any_hit_ray_packet(&through_vertex, all, &mut NoCount), all);
        }
    });
    assert_eq!(allocated, 0, "{allocated} allocations in packet queries");
    assert!(hits as usize > rays.len(), "{hits}");
}
