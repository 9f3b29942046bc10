//! The whole-packet triangle tests (`block_avx512`, `block_avx2`) against the single-ray block
//! test (`intersect_block`), ray by ray and bit for bit: the same lanes special (left to the
//! scalar test), the same hits, at the same distance and barycentrics. The rays are vertical or
//! nearly so, from the points of a grid, and the triangles' vertices lie on the same grid, so that
//! rays pass exactly through vertices and along edges, where the edge functions are zero and the
//! lanes are special.
#![cfg(target_arch = "x86_64")]

use englobe::accel::wide::isa::Isa;
use englobe::accel::wide::packet_kernels::{PACKET, PacketRays};
use englobe::accel::wide::packet_triangles::{PacketBest, PacketTriRays, block_avx2, block_avx512, shared_axes_avx512};
use englobe::accel::wide::triangles::{TriBlock, TriRay, intersect_block};
use englobe::{Ray, Vec3};
use rand::{RngExt, SeedableRng};
use rand_pcg::Pcg32;

#[test]
fn whole_packet_triangle_tests_answer_as_the_single_ray_block_test() {
    let isas: Vec<Isa> = Isa::available().into_iter().filter(|&i| i != Isa::Portable).collect();
    let mut rng = Pcg32::seed_from_u64(0xb10c_4a11);
    let (mut hits, mut specials, mut misses) = (0, 0, 0);
    for round in 0..6_000 {
        let scale = [1.0f32, 0.25, 1024.0][round % 3];
        let mut grid = |n: i32| rng.random_range(-n..=n) as f32 * scale;
        let triangle = [
            Vec3::new(grid(2), grid(2), grid(1)),
            Vec3::new(grid(2), grid(2), grid(1)),
            Vec3::new(grid(2), grid(2), grid(1)),
        ];
        if (triangle[1] - triangle[0]).cross(triangle[2] - triangle[0]) == Vec3::ZERO {
            continue;
        }
        let block = TriBlock::new(&[(7, triangle)]);
        // Every ray goes down (or up) `z` more steeply than along the other axes, so that the
        // packet shares the watertight test's axes.
        let down = [1.0f32, -1.0][round % 2];
        let rays: Vec<Ray> = (0..1 + rng.random_range(0..PACKET))
            .map(|_| {
                let mut step = |n: i32| rng.random_range(-n..=n) as f32;
                let origin = Vec3::new(step(2) * scale, step(2) * scale, -4.0 * down * scale);
                let lean = if round % 4 < 2 { Vec3::ZERO } else { Vec3::new(step(1), step(1), 0.0) * 0.25 };
                let t_max = [f32::INFINITY, 4.0 * scale, 5.0 * scale][rng.random_range(0..3)];
                Ray::segment(origin, Vec3::new(0.0, 0.0, down) + lean, 0.0, t_max)
            })
            .collect();
        let packet = PacketRays::new(&rays);
        let active = (1u32 << rays.len()) - 1;
        let axes = PacketTriRays::shared_axes(&packet, active).expect("the rays share their axes");
        let r = PacketTriRays::new(&packet, active, axes);
        for &isa in &isas {
            let mut best = PacketBest::new(&packet.t_max);
            // SAFETY: each block test runs only where the processor has its instruction set.
            let (hit, special) = unsafe {
                match isa {
                    Isa::Avx512 => block_avx512(&block, &packet, &r, active, &mut best, true),
                    _ => block_avx2(&block, &packet, &r, active, &mut best, true),
                }
            };
            for (i, ray) in rays.iter().enumerate() {
                let expected = intersect_block(&block, &TriRay::new(ray), ray.t_max);
                let expected_special = expected.is_some_and(|b| b.special & 1 != 0);
                assert_eq!(special >> i & 1 != 0, expected_special, "{isa}: special, {ray:?}, {triangle:?}");
                if expected_special {
                    specials += 1;
                    continue;
                }
                let expected_hit = expected.filter(|b| b.hit & 1 != 0).map(|b| b.lane(0));
                assert_eq!(hit >> i & 1 != 0, expected_hit.is_some(), "{isa}: hit, {ray:?}, {triangle:?}");
                match expected_hit {
                    Some(h) => {
                        let got = best.hit(i).expect("the closest hit kept");
                        assert_eq!(
                            [got.t, got.u, got.v].map(f32::to_bits),
                            [h.t, h.u, h.v].map(f32::to_bits),
                            "{isa}: {ray:?}, {triangle:?}"
                        );
                        assert_eq!(got.prim, 7);
                        hits += 1;
                    }
                    None => misses += 1,
                }
            }
        }
    }
    if !isas.is_empty() {
        assert!(hits > 2_500 && specials > 1_000 && misses > 3_000, "{hits} hits, {specials} special, {misses} misses");
    }
}

#[test]
fn packets_share_their_axes_with_avx512_as_in_the_portable_form() {
    if !Isa::available().contains(&Isa::Avx512) {
        return;
    }
    // Components equal in magnitude (ties between axes), zeros of both signs, a NaN now and then:
    // every way the choice of the largest axis and its sign can go.
    let values = [1.0f32, -1.0, 0.5, -0.5, 0.0, -0.0, 2.0, -2.0, f32::NAN];
    let mut rng = Pcg32::seed_from_u64(0xa3e5_5a3e);
    let (mut shared, mut not) = (0, 0);
    for round in 0..20_000 {
        // Most packets from a few directions, so that many share their axes.
        let few: Vec<Vec3> = (0..1 + round % 3)
            .map(|_| {
                let mut pick = || values[rng.random_range(0..values.len())];
                Vec3::new(pick(), pick(), pick())
            })
            .collect();
        let rays: Vec<Ray> = (0..1 + rng.random_range(0..PACKET))
            .map(|_| Ray::new(Vec3::ZERO, few[rng.random_range(0..few.len())]))
            .collect();
        let packet = PacketRays::new(&rays);
        let active = rng.random_range(0..1u32 << rays.len());
        let expected = PacketTriRays::shared_axes(&packet, active);
        // SAFETY: the processor has AVX-512 (checked above).
        assert_eq!(unsafe { shared_axes_avx512(&packet, active) }, expected, "lanes {active:b} of {rays:?}");
        shared += expected.is_some() as u32;
        not += expected.is_none() as u32;
    }
    assert!(shared > 5_000 && not > 5_000, "{shared} shared, {not} not");
}
