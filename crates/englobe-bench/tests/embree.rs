//! Embree through englobe's own FFI: single rays and 16-ray packets (full and partial) give the
//! expected answers on a hand-made scene, the same as each other. Only with the `embree` feature.

#![cfg(feature = "embree")]

use englobe::{TriangleMesh, Vec3};
use englobe_bench::adapters::embree::{EmbreePacket16, EmbreeSingle};
use englobe_bench::{BenchRay, BenchScene, Library, RayResult};

/// Two unit squares facing +z, at z = 0 (triangles 0 and 1) and z = -1 (triangles 2 and 3).
fn two_squares() -> BenchScene {
    let mut positions = Vec::new();
    for z in [0.0, -1.0] {
        positions.extend([
            Vec3::new(0.0, 0.0, z),
            Vec3::new(1.0, 0.0, z),
            Vec3::new(1.0, 1.0, z),
            Vec3::new(0.0, 1.0, z),
        ]);
    }
    let tris = vec![[0, 1, 2], [0, 2, 3], [4, 5, 6], [4, 6, 7]];
    BenchScene::from_mesh("squares", TriangleMesh::new(positions, tris).unwrap())
}

fn rays() -> Vec<BenchRay> {
    // 37 rays (two full packets and a partial one): hits on the front square, segments that end
    // before it, rays that miss beside it and rays from between the squares going both ways.
    (0..37)
        .map(|i| {
            let x = 0.1 + 0.02 * i as f32;
            match i % 4 {
                0 => BenchRay::new(Vec3::new(x, 0.3, 2.0), Vec3::NEG_Z),
                1 => BenchRay { t_max: 1.5, ..BenchRay::new(Vec3::new(x, 0.3, 2.0), Vec3::NEG_Z) },
                2 => BenchRay::new(Vec3::new(x + 2.0, 0.3, 2.0), Vec3::NEG_Z),
                _ => BenchRay::new(Vec3::new(x, 0.7, -0.5), if i % 8 == 3 { Vec3::Z } else { Vec3::NEG_Z }),
            }
        })
        .collect()
}

fn expected(i: usize) -> RayResult {
    // A point (x, y) of a square lies in its second triangle above the diagonal, else in its first
    // (no ray passes through the diagonal).
    let x = 0.1 + 0.02 * i as f32;
    let triangle = |y: f32| if y > x { 1 } else { 0 };
    match i % 4 {
        0 => RayResult::hit(2.0, triangle(0.3)),
        1 | 2 => RayResult::MISS,
        _ if i % 8 == 3 => RayResult::hit(0.5, triangle(0.7)),
        _ => RayResult::hit(0.5, triangle(0.7) + 2),
    }
}

fn check(library: &dyn Library) {
    let rays = rays();
    let mut closest = vec![RayResult::MISS; rays.len()];
    let mut any = vec![false; rays.len()];
    library.closest_hits(&rays, &mut closest);
    library.any_hits(&rays, &mut any);
    for (i, (c, a)) in closest.iter().zip(&any).enumerate() {
        let want = expected(i);
        assert_eq!(c.prim, want.prim, "ray {i}: {c:?}, expected {want:?}");
        if want.is_hit() {
            assert!((c.t - want.t).abs() < 1e-6, "ray {i}: {c:?}");
        }
        assert_eq!(*a, want.is_hit(), "ray {i}");
    }
}

#[test]
fn single_rays_and_packets_answer_right() {
    let scene = two_squares();
    for robust in [false, true] {
        for threads in [1, 2] {
            let single = EmbreeSingle::build(&scene, threads, robust).unwrap();
            assert!(single.structure().contains("Embree 3."), "{}", single.structure());
            check(&single);
            let packets = EmbreePacket16::build(&scene, threads, robust).unwrap();
            assert_eq!(packets.packet_width(), 16);
            check(&packets);
        }
    }
}
