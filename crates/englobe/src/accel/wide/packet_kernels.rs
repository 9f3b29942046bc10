//! The slab test of a wide node's children against a packet of up to [`PACKET`] rays: one child
//! box at a time, all the packet's rays in the lanes of one vector (sixteen with AVX-512, two
//! halves of eight with AVX2). This is the packet traversal's node test of Wald, Slusallek,
//! Benthin and Wagner (2001), "Interactive Rendering with Coherent Ray Tracing", on the eight-wide
//! nodes of Embree's hybrid traversal (Wald, Woop, Benthin, Johnson and Ernst 2014, "Embree: A
//! Kernel Framework for Efficient CPU Ray Tracing", section 4): a node's 48 planes are each loaded
//! once for the whole packet.
//!
//! Each lane computes exactly what the single-ray test computes for its ray
//! ([`super::node::child_entry_scalar`]): the near and far planes chosen by the sign of the lane's
//! inverse direction, the same differences and products, the same NaN rule. So a packet enters
//! a child for a ray exactly when that ray's own query would, at the same distance; the scalar
//! kernel here is the reference the SIMD ones are tested against, lane by lane.
//!
//! The kernels are `unsafe` only because the x86 ones need their instruction set (see
//! [`super::kernels`]).

use super::node::{EMPTY, WIDTH, WideNode};
pub use super::packet_rays::{Lanes, PACKET, PacketRays};

/// What a node test gives: for each child entered by some ray, the rays that enter it and their
/// entry distances.
#[derive(Clone, Copy, Debug)]
#[repr(C, align(64))]
pub struct ChildHits {
    /// Entry distance of each ray into each child; NaN for the rays that do not enter it. Read
    /// only for the children of the returned mask.
    pub dist: [Lanes; WIDTH],
    /// The rays entering each child (bit per ray).
    pub rays: [u32; WIDTH],
    /// The order of the walk: the least entry distance into each child over its rays, or, in
    /// the SIMD kernels of a packet with an interval ([`PacketRays::bound`]), the interval's lower
    /// bound of every ray's entry distance (no greater, and made without a reduction per child).
    pub near: [f32; WIDTH],
}

impl ChildHits {
    /// Nothing yet.
    pub const NONE: ChildHits =
        ChildHits { dist: [Lanes([f32::NAN; PACKET]); WIDTH], rays: [0; WIDTH], near: [0.0; WIDTH] };
}

/// A slab test of every child of a node against a packet.
pub trait PacketKernel: Copy {
    /// Tests the rays of `active` against the node's children within `t_min..=limit`, each ray
    /// with its own `limit` lane: bit `c` of the result is set if some ray enters child `c`, and
    /// `out` then says which and where.
    ///
    /// # Safety
    /// As [`super::kernels::NodeKernel::children`].
    unsafe fn children(
        self,
        node: &WideNode,
        rays: &PacketRays,
        active: u32,
        limit: &Lanes,
        out: &mut ChildHits,
    ) -> u32;

    /// The rays of `active` whose entry distance `dist` is within their `limit` (a NaN distance,
    /// a ray that did not enter, never is).
    ///
    /// # Safety
    /// As [`PacketKernel::children`].
    unsafe fn within(self, dist: &Lanes, limit: &Lanes, active: u32) -> u32;
}

/// One ray at a time, as the single-ray scalar test: the reference, and the kernel of processors
/// without a vector instruction set of the crate's.
#[derive(Clone, Copy, Debug)]
pub struct ScalarPacket;

impl PacketKernel for ScalarPacket {
    #[inline(always)]
    unsafe fn children(
        self,
        node: &WideNode,
        rays: &PacketRays,
        active: u32,
        limit: &Lanes,
        out: &mut ChildHits,
    ) -> u32 {
        let mut mask = 0;
        for c in 0..WIDTH {
            if node.children[c] == EMPTY {
                continue;
            }
            let (mut entered, mut near) = (0, f32::INFINITY);
            for i in 0..PACKET {
                let mut d = f32::NAN;
                if active >> i & 1 != 0 {
                    let (mut enter, mut exit) = (rays.t_min.0[i], limit.0[i]);
                    for a in 0..3 {
                        let down = (rays.down[a] >> i & 1) as usize;
                        let (near_row, far_row) = (2 * a + down, 2 * a + 1 - down);
                        let o = rays.origin[a].0[i];
                        let t_near = (o - node.bounds[near_row][c]) * -rays.inv_dir[a].0[i];
                        let t_far = (o - node.bounds[far_row][c]) * -rays.inv_far[a].0[i];
                        enter = if t_near > enter { t_near } else { enter };
                        exit = if t_far < exit { t_far } else { exit };
                    }
                    if enter <= exit {
                        d = enter;
                        entered |= 1 << i;
                        near = near.min(enter);
                    }
                }
                out.dist[c].0[i] = d;
            }
            if entered != 0 {
                mask |= 1 << c;
                out.rays[c] = entered;
                out.near[c] = near;
            }
        }
        mask
    }

    #[inline(always)]
    unsafe fn within(self, dist: &Lanes, limit: &Lanes, active: u32) -> u32 {
        let mut m = 0;
        for i in 0..PACKET {
            m |= ((dist.0[i] <= limit.0[i]) as u32) << i;
        }
        m & active
    }
}

#[cfg(target_arch = "x86_64")]
pub use x86::{Avx2Packet, Avx512Packet};

#[cfg(target_arch = "x86_64")]
mod x86 {
    use std::arch::x86_64::*;

    use super::{ChildHits, EMPTY, Lanes, PACKET, PacketKernel, PacketRays, WIDTH, WideNode};

    /// The children worth a ray test: those the packet's interval does not cull, with the
    /// interval's entry distances in `near` (then `true`), or every used slot if it has none.
    ///
    /// # Safety
    /// The caller is compiled with AVX and runs on a processor that has it.
    #[inline(always)]
    unsafe fn candidates(node: &WideNode, rays: &PacketRays, near: &mut [f32; WIDTH]) -> (u32, bool) {
        match &rays.interval {
            // SAFETY: the caller's guarantee.
            Some(interval) => (unsafe { interval.candidates_avx(node, near) }, true),
            None => ((0..WIDTH).filter(|&c| node.children[c] != EMPTY).fold(0, |m, c| m | 1 << c), false),
        }
    }

    /// Sixteen lanes with AVX-512: the whole packet in one register, the direction signs in mask
    /// registers.
    #[derive(Clone, Copy, Debug)]
    pub struct Avx512Packet;

    impl PacketKernel for Avx512Packet {
        #[inline(always)]
        unsafe fn children(
            self,
            node: &WideNode,
            rays: &PacketRays,
            active: u32,
            limit: &Lanes,
            out: &mut ChildHits,
        ) -> u32 {
            // SAFETY (for the whole function): the caller guarantees AVX-512 F; every `Lanes` is
            // 64 bytes aligned to 64, so the aligned loads and stores are in bounds and aligned.
            unsafe {
                let load = |l: &Lanes| _mm512_load_ps(l.0.as_ptr());
                // The inverses negated, so that each plane is subtracted from the origins straight
                // from memory, broadcast by the subtraction (see `child_entry_scalar`). The walk
                // keeps them in registers from node to node: the negation is made once.
                let sign = _mm512_set1_epi32(i32::MIN);
                let negated = |l: &Lanes| _mm512_castsi512_ps(_mm512_xor_si512(_mm512_castps_si512(load(l)), sign));
                let o = [load(&rays.origin[0]), load(&rays.origin[1]), load(&rays.origin[2])];
                let inv = [negated(&rays.inv_dir[0]), negated(&rays.inv_dir[1]), negated(&rays.inv_dir[2])];
                let inv_far = [negated(&rays.inv_far[0]), negated(&rays.inv_far[1]), negated(&rays.inv_far[2])];
                let down = rays.down.map(|d| d as __mmask16);
                let (t_min, lim) = (load(&rays.t_min), load(limit));
                let nan = _mm512_set1_ps(f32::NAN);
                // When the active rays go the same way along every axis (a camera's tile, nearly
                // always), each axis's near and far rows are the same for all of them: no blend.
                let same_way = rays.down.iter().all(|&d| d & active == 0 || d & active == active);
                let rows = rays.down.map(|d| (d & active != 0) as usize);
                let mut mask = 0;
                let (mut candidates, ordered) = candidates(node, rays, &mut out.near);
                while candidates != 0 {
                    let c = candidates.trailing_zeros() as usize;
                    candidates &= candidates - 1;
                    let (mut enter, mut exit) = (t_min, lim);
                    for a in 0..3 {
                        let (t_near, t_far) = if same_way {
                            let near = _mm512_set1_ps(node.bounds[2 * a + rows[a]][c]);
                            let far = _mm512_set1_ps(node.bounds[2 * a + 1 - rows[a]][c]);
                            (
                                _mm512_mul_ps(_mm512_sub_ps(o[a], near), inv[a]),
                                _mm512_mul_ps(_mm512_sub_ps(o[a], far), inv_far[a]),
                            )
                        } else {
                            let lo = _mm512_sub_ps(o[a], _mm512_set1_ps(node.bounds[2 * a][c]));
                            let hi = _mm512_sub_ps(o[a], _mm512_set1_ps(node.bounds[2 * a + 1][c]));
                            // The lanes going down take the upper plane as the near one.
                            (
                                _mm512_mul_ps(_mm512_mask_blend_ps(down[a], lo, hi), inv[a]),
                                _mm512_mul_ps(_mm512_mask_blend_ps(down[a], hi, lo), inv_far[a]),
                            )
                        };
                        // `max(a, b)` is `a > b ? a : b`, `b` when either is NaN: the scalar rule.
                        enter = _mm512_max_ps(t_near, enter);
                        exit = _mm512_min_ps(t_far, exit);
                    }
                    let entered = _mm512_mask_cmp_ps_mask::<_CMP_LE_OQ>(active as __mmask16, enter, exit);
                    if entered != 0 {
                        mask |= 1 << c;
                        _mm512_store_ps(out.dist[c].0.as_mut_ptr(), _mm512_mask_blend_ps(entered, nan, enter));
                        out.rays[c] = entered as u32;
                        if !ordered {
                            out.near[c] = _mm512_mask_reduce_min_ps(entered, enter);
                        }
                    }
                }
                mask
            }
        }

        #[inline(always)]
        unsafe fn within(self, dist: &Lanes, limit: &Lanes, active: u32) -> u32 {
            // SAFETY: AVX-512 F is guaranteed by the caller; `Lanes` are aligned to 64.
            unsafe {
                let (d, l) = (_mm512_load_ps(dist.0.as_ptr()), _mm512_load_ps(limit.0.as_ptr()));
                _mm512_mask_cmp_ps_mask::<_CMP_LE_OQ>(active as __mmask16, d, l) as u32
            }
        }
    }

    /// Two halves of eight lanes with AVX2.
    #[derive(Clone, Copy, Debug)]
    pub struct Avx2Packet;

    const HALF: usize = PACKET / 2;

    impl PacketKernel for Avx2Packet {
        #[inline(always)]
        unsafe fn children(
            self,
            node: &WideNode,
            rays: &PacketRays,
            active: u32,
            limit: &Lanes,
            out: &mut ChildHits,
        ) -> u32 {
            // SAFETY (for the whole function): the caller guarantees AVX2; each half of a `Lanes`
            // is 32 bytes at an offset of 0 or 32 from a 64-aligned start.
            unsafe {
                let zero = _mm256_setzero_ps();
                let nan = _mm256_set1_ps(f32::NAN);
                let mut entered = [0u32; WIDTH];
                let mut near = [_mm256_set1_ps(f32::INFINITY); WIDTH];
                let (candidates, ordered) = candidates(node, rays, &mut out.near);
                for h in 0..2 {
                    // Both halves run even when one has no active ray, so that every lane of an
                    // entered child's distances is written.
                    let active_h = (active >> (HALF * h)) & 0xff;
                    let load = |l: &Lanes| _mm256_load_ps(l.0.as_ptr().add(HALF * h));
                    // The inverses negated, as the scalar test has them (see `child_entry_scalar`;
                    // AVX2 cannot subtract a broadcast plane from memory, so this kernel gains
                    // nothing from the order and pays six sign flips per half).
                    let sign = _mm256_castsi256_ps(_mm256_set1_epi32(i32::MIN));
                    let negated = |l: &Lanes| _mm256_xor_ps(load(l), sign);
                    let o = [load(&rays.origin[0]), load(&rays.origin[1]), load(&rays.origin[2])];
                    let inv = [negated(&rays.inv_dir[0]), negated(&rays.inv_dir[1]), negated(&rays.inv_dir[2])];
                    let inv_far = [negated(&rays.inv_far[0]), negated(&rays.inv_far[1]), negated(&rays.inv_far[2])];
                    // All ones in the lanes going down (`inv < 0`, as `PacketRays::down` says; the
                    // negated inverse above zero).
                    let down = inv.map(|v| _mm256_cmp_ps::<_CMP_GT_OQ>(v, zero));
                    let (t_min, lim) = (load(&rays.t_min), load(limit));
                    let mut left = candidates;
                    while left != 0 {
                        let c = left.trailing_zeros() as usize;
                        left &= left - 1;
                        let (mut enter, mut exit) = (t_min, lim);
                        for a in 0..3 {
                            let lo = _mm256_sub_ps(o[a], _mm256_set1_ps(node.bounds[2 * a][c]));
                            let hi = _mm256_sub_ps(o[a], _mm256_set1_ps(node.bounds[2 * a + 1][c]));
                            let t_near = _mm256_mul_ps(_mm256_blendv_ps(lo, hi, down[a]), inv[a]);
                            let t_far = _mm256_mul_ps(_mm256_blendv_ps(hi, lo, down[a]), inv_far[a]);
                            enter = _mm256_max_ps(t_near, enter);
                            exit = _mm256_min_ps(t_far, exit);
                        }
                        let m = _mm256_movemask_ps(_mm256_cmp_ps::<_CMP_LE_OQ>(enter, exit)) as u32 & active_h;
                        if m != 0 {
                            let keep = _mm256_castsi256_ps(_mm256_cmpgt_epi32(
                                _mm256_and_si256(
                                    _mm256_set1_epi32(m as i32),
                                    _mm256_setr_epi32(1, 2, 4, 8, 16, 32, 64, 128),
                                ),
                                _mm256_setzero_si256(),
                            ));
                            let d = _mm256_blendv_ps(nan, enter, keep);
                            _mm256_store_ps(out.dist[c].0.as_mut_ptr().add(HALF * h), d);
                            // NaN lanes lose every `min` (the second operand is returned).
                            near[c] = _mm256_min_ps(d, near[c]);
                            entered[c] |= m << (HALF * h);
                        } else {
                            _mm256_store_ps(out.dist[c].0.as_mut_ptr().add(HALF * h), nan);
                        }
                    }
                }
                let mut mask = 0;
                for c in 0..WIDTH {
                    if entered[c] != 0 {
                        mask |= 1 << c;
                        out.rays[c] = entered[c];
                        if ordered {
                            continue;
                        }
                        let mut n = [0.0f32; HALF];
                        _mm256_storeu_ps(n.as_mut_ptr(), near[c]);
                        out.near[c] = n.iter().fold(f32::INFINITY, |a, &b| a.min(b));
                    }
                }
                mask
            }
        }

        #[inline(always)]
        unsafe fn within(self, dist: &Lanes, limit: &Lanes, active: u32) -> u32 {
            // SAFETY: AVX is guaranteed by the caller; the halves are aligned to 32.
            unsafe {
                let mut m = 0;
                for h in 0..2 {
                    let d = _mm256_load_ps(dist.0.as_ptr().add(HALF * h));
                    let l = _mm256_load_ps(limit.0.as_ptr().add(HALF * h));
                    m |= (_mm256_movemask_ps(_mm256_cmp_ps::<_CMP_LE_OQ>(d, l)) as u32) << (HALF * h);
                }
                m & active
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use glam::Vec3;
    use rand::{RngExt, SeedableRng};
    use rand_pcg::Pcg32;

    use super::*;
    use crate::accel::wide::isa::Isa;
    use crate::accel::wide::node::{NodeRay, child_entry_scalar, reach};
    use crate::accel::wide::packet_interval::PacketInterval;
    use crate::{Aabb, Ray};

    /// The kernel of `isa` on the packet, its lanes compared with the scalar packet kernel's, and
    /// those with the single-ray scalar test, bit for bit.
    fn check(isa: Isa, node: &WideNode, rays: &[Ray], active: u32, bounded: bool) -> u32 {
        let mut packet = PacketRays::new(rays);
        if bounded {
            packet.bound(active);
        }
        let limit = Lanes(std::array::from_fn(|i| rays.get(i).map_or(0.0, |r| reach(r.t_max))));
        let mut got = ChildHits::NONE;
        // SAFETY: each kernel runs only if the processor has its instruction set.
        let mask = unsafe {
            match isa {
                Isa::Portable => ScalarPacket.children(node, &packet, active, &limit, &mut got),
                #[cfg(target_arch = "x86_64")]
                Isa::Avx2 => Avx2Packet.children(node, &packet, active, &limit, &mut got),
                #[cfg(target_arch = "x86_64")]
                Isa::Avx512 => Avx512Packet.children(node, &packet, active, &limit, &mut got),
                #[cfg(not(target_arch = "x86_64"))]
                _ => unreachable!(),
            }
        };
        let mut entered = 0;
        for slot in 0..WIDTH {
            let mut rays_in = 0;
            let mut near = f32::INFINITY;
            for (i, ray) in rays.iter().enumerate() {
                let expected = if active >> i & 1 != 0 {
                    child_entry_scalar(node, slot, &NodeRay::new(ray), limit.0[i])
                } else {
                    None
                };
                if let Some(d) = expected {
                    rays_in |= 1 << i;
                    near = near.min(d);
                }
                if mask >> slot & 1 != 0 {
                    let lane = got.dist[slot].0[i];
                    let got_lane = (!lane.is_nan()).then_some(lane);
                    assert_eq!(got_lane.map(f32::to_bits), expected.map(f32::to_bits), "{isa}: slot {slot}, ray {i}");
                    // SAFETY: as above.
                    let within = unsafe {
                        match isa {
                            Isa::Portable => ScalarPacket.within(&got.dist[slot], &limit, active),
                            #[cfg(target_arch = "x86_64")]
                            Isa::Avx2 => Avx2Packet.within(&got.dist[slot], &limit, active),
                            #[cfg(target_arch = "x86_64")]
                            Isa::Avx512 => Avx512Packet.within(&got.dist[slot], &limit, active),
                            #[cfg(not(target_arch = "x86_64"))]
                            _ => unreachable!(),
                        }
                    };
                    assert_eq!(within >> i & 1 != 0, expected.is_some(), "{isa}: within, slot {slot}, ray {i}");
                }
            }
            assert_eq!(mask >> slot & 1 != 0, rays_in != 0, "{isa}: slot {slot}");
            if rays_in != 0 {
                assert_eq!(got.rays[slot], rays_in, "{isa}: rays of slot {slot}");
                if packet.interval.is_some() && isa != Isa::Portable {
                    assert!(got.near[slot] <= near, "{isa}: bound of the nearest entry of slot {slot}");
                } else {
                    assert_eq!(got.near[slot], near, "{isa}: nearest entry of slot {slot}");
                }
            }
            entered += rays_in.count_ones();
        }
        entered
    }

    #[test]
    fn every_packet_kernel_agrees_bit_for_bit_with_the_single_ray_test() {
        // As the single-ray kernels' test: integer planes, axis-parallel directions of both
        // signs and zeros of both signs, so that origins on planes and flat boxes occur; each
        // packet mixes directions, and some rays are left out of the active mask. Every other
        // packet goes one way along each axis, with no zero component, and gets an interval.
        let mut rng = Pcg32::seed_from_u64(0x0009_ace7);
        let next = &mut move |n: u32| rng.random_range(0..n);
        fn point(next: &mut impl FnMut(u32) -> u32, v: &[f32]) -> Vec3 {
            let n = v.len() as u32;
            Vec3::new(v[next(n) as usize], v[next(n) as usize], v[next(n) as usize])
        }
        let values = [-2.0f32, -1.0, -0.0, 0.0, 0.5, 1.0, 2.0];
        let dirs = [-1.0f32, -0.0, 0.0, 0.3, 1.0];
        for isa in Isa::available() {
            let (mut entered, mut bounded) = (0, 0);
            for round in 0..6_000 {
                let mut node = WideNode::EMPTY_NODE;
                let children = 1 + next(WIDTH as u32) as usize;
                for slot in 0..children {
                    let (a, b) = (point(next, &values), point(next, &values));
                    node.set_child(slot, &Aabb::new(a.min(b), a.max(b)), slot as u32, 0);
                }
                let n = 1 + next(PACKET as u32) as usize;
                let one_way = round % 2 == 1;
                let signs = point(next, &[-1.0, 1.0]);
                let mut rays = Vec::new();
                for _ in 0..n {
                    let o = point(next, &values) * 1.5;
                    let d = if one_way { point(next, &[0.3, 0.5, 1.0]) * signs } else { point(next, &dirs) };
                    let d = if d == Vec3::ZERO { Vec3::X } else { d };
                    rays.push(Ray::segment(o, d, 0.0, [f32::INFINITY, 1.0, 2.5][next(3) as usize]));
                }
                let active = (next(1 << 16) | next(1 << 16)) & ((1u32 << n) - 1);
                entered += check(isa, &node, &rays, active, one_way);
                bounded += (one_way && PacketInterval::new(&rays).is_some()) as u32;
            }
            assert!(entered > 6_000 && bounded == 3_000, "{isa}: {entered} entered, {bounded} bounded");
        }
    }
}
