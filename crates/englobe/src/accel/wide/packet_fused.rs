//! The fused node test of [`super::fused`] for packets, with AVX-512: one multiply-add per plane
//! and lane, `plane * inv + c` with `c = -origin * inv` made once per packet, in the form of Wald,
//! Woop, Benthin, Johnson and Ernst (2014), "Embree: A Kernel Framework for Efficient CPU Ray
//! Tracing", where the exact-order packet test ([`super::packet_kernels::Avx512Packet`]) takes a
//! difference and a product per plane. A child's test for the whole packet is then six
//! multiply-adds and six `max` or `min`, from its planes' broadcasts to the mask of the lanes
//! entered, instead of six differences, six products and six `max` or `min`.
//!
//! Each lane's constants are those the single-ray query makes for its ray
//! ([`super::fused::FusedPlanes`], each rounded its safe way), and each lane computes what that
//! query's fused test computes ([`super::fused::child_distances_fused_scalar`]), bit for bit, the
//! entry and the exit each reduced in the same two steps. So the form's argument holds lane by
//! lane: every box around a hit that the exact-order test accepts is entered. The packet takes this
//! test when the form applies to every ray it traces ([`PacketPlanes::new_avx512`]); a packet with
//! a ray it does not apply to takes the exact-order test, as a single ray does.
//!
//! The packet's interval ([`super::packet_interval`]) still culls the children no ray's
//! exact-order test can enter, before any lane is tested: such a child holds no hit for any of the
//! rays, though a ray's fused test, a few roundings wider, might have entered it. The rest of the
//! children are tested lane by lane as above.

use super::fused::{FusedPlanes, LARGEST, applies_to};
use super::node::NodeRay;
use super::packet_rays::{Lanes, PACKET, PacketRays};

/// The fused test's constants of a packet's rays, one [`Lanes`] row per axis.
#[derive(Clone, Copy, Debug, PartialEq)]
#[repr(C, align(64))]
pub struct PacketPlanes {
    /// Per axis, each lane's `-origin * inv` rounded down ([`FusedPlanes::near`]).
    pub near: [Lanes; 3],
    /// Per axis, each lane's `-origin * inv_far + 2^-126` rounded up ([`FusedPlanes::far`]).
    pub far: [Lanes; 3],
}

impl PacketPlanes {
    /// The constants of the rays of `active` in `rays`, each lane's made as
    /// [`FusedPlanes::new`] makes them for its ray, if the fused form applies to every one of
    /// them; the other lanes hold zeros. The reference [`PacketPlanes::new_avx512`] matches.
    pub fn new(rays: &PacketRays, active: u32) -> Option<Self> {
        let mut planes = PacketPlanes { near: [Lanes([0.0; PACKET]); 3], far: [Lanes([0.0; PACKET]); 3] };
        for i in (0..PACKET).filter(|&i| active >> i & 1 != 0) {
            let ray = NodeRay::new(&rays.ray(i));
            if !applies_to(&ray) {
                return None;
            }
            let lane = FusedPlanes::new(&ray);
            for a in 0..3 {
                (planes.near[a].0[i], planes.far[a].0[i]) = (lane.near[a], lane.far[a]);
            }
        }
        Some(planes)
    }
}

#[cfg(target_arch = "x86_64")]
pub use x86::Avx512FusedPacket;

#[cfg(target_arch = "x86_64")]
mod x86 {
    use std::arch::x86_64::*;

    use super::super::node::WideNode;
    use super::super::packet_kernels::{ChildHits, PacketKernel, Slabs16, children16, planes16, same_rows, within16};
    use super::{LARGEST, Lanes, PacketPlanes, PacketRays};

    impl PacketPlanes {
        /// [`PacketPlanes::new`] sixteen lanes at once: the form's conditions ([`super::applies_to`])
        /// checked in every lane, and each constant one multiply-add rounded down or up, as
        /// [`super::FusedPlanes::new_avx512`] makes it for one ray.
        ///
        /// # Safety
        /// The caller is compiled with AVX-512 F and runs on a processor that has it.
        #[inline(always)]
        pub unsafe fn new_avx512(rays: &PacketRays, active: u32) -> Option<Self> {
            const DOWN: i32 = _MM_FROUND_TO_NEG_INF | _MM_FROUND_NO_EXC;
            const UP: i32 = _MM_FROUND_TO_POS_INF | _MM_FROUND_NO_EXC;
            // SAFETY (for the whole function): the caller's guarantee; every row is 64 bytes
            // aligned to 64.
            unsafe {
                let (zero, bound) = (_mm512_setzero_ps(), _mm512_set1_ps(LARGEST));
                let floor = _mm512_set1_ps(f32::MIN_POSITIVE);
                // `t_min >= 0`, and below the bound each far factor and its product with the
                // origin (false for NaN and the infinities), in every lane traced.
                let mut applies = _mm512_cmp_ps_mask::<_CMP_GE_OQ>(_mm512_load_ps(rays.t_min.0.as_ptr()), zero);
                let mut planes = PacketPlanes { near: [Lanes([0.0; 16]); 3], far: [Lanes([0.0; 16]); 3] };
                for a in 0..3 {
                    let o = _mm512_load_ps(rays.origin[a].0.as_ptr());
                    let inv = _mm512_load_ps(rays.inv_dir[a].0.as_ptr());
                    let inv_far = _mm512_load_ps(rays.inv_far[a].0.as_ptr());
                    let product = _mm512_abs_ps(_mm512_mul_ps(o, inv_far));
                    applies &= _mm512_cmp_ps_mask::<_CMP_LT_OQ>(_mm512_abs_ps(inv_far), bound)
                        & _mm512_cmp_ps_mask::<_CMP_LT_OQ>(product, bound);
                    // `-(o * inv) + 0` and `-(o * inv_far) + 2^-126`, each rounded once, its way;
                    // zeros in the lanes not traced.
                    let k = active as __mmask16;
                    let near = _mm512_maskz_fnmadd_round_ps::<DOWN>(k, o, inv, zero);
                    let far = _mm512_maskz_fnmadd_round_ps::<UP>(k, o, inv_far, floor);
                    _mm512_store_ps(planes.near[a].0.as_mut_ptr(), near);
                    _mm512_store_ps(planes.far[a].0.as_mut_ptr(), far);
                }
                if applies as u32 & active == active { Some(planes) } else { None }
            }
        }
    }

    /// The fused test of one child for a packet's lanes (see the module documentation).
    #[derive(Clone, Copy)]
    struct Fused16 {
        inv: [__m512; 3],
        inv_far: [__m512; 3],
        near: [__m512; 3],
        far: [__m512; 3],
        t_min: __m512,
        down: [__mmask16; 3],
        rows: Option<[usize; 3]>,
    }

    impl Slabs16 for Fused16 {
        #[inline(always)]
        unsafe fn slabs(self, node: &WideNode, c: usize, lim: __m512) -> (__m512, __m512) {
            // SAFETY: the caller's guarantee.
            unsafe {
                let (mut near, mut far) = ([_mm512_setzero_ps(); 3], [_mm512_setzero_ps(); 3]);
                for a in 0..3 {
                    let (near_plane, far_plane) = planes16(node, c, a, self.rows, self.down[a]);
                    near[a] = _mm512_fmadd_ps(near_plane, self.inv[a], self.near[a]);
                    far[a] = _mm512_fmadd_ps(far_plane, self.inv_far[a], self.far[a]);
                }
                // The order of `child_distances_fused_scalar` (`max(a, b)` is `a > b ? a : b`):
                // the same bits, zeros' signs included.
                let enter = _mm512_max_ps(_mm512_max_ps(near[0], near[1]), _mm512_max_ps(near[2], self.t_min));
                let exit = _mm512_min_ps(_mm512_min_ps(far[0], far[1]), _mm512_min_ps(far[2], lim));
                (enter, exit)
            }
        }
    }

    /// The fused node test with AVX-512, for a packet whose traced rays the form applies to, with
    /// their constants ([`PacketPlanes::new_avx512`]).
    #[derive(Clone, Copy, Debug)]
    pub struct Avx512FusedPacket<'a>(pub &'a PacketPlanes);

    impl PacketKernel for Avx512FusedPacket<'_> {
        #[inline(always)]
        unsafe fn children(
            self,
            node: &WideNode,
            rays: &PacketRays,
            active: u32,
            limit: &Lanes,
            out: &mut ChildHits,
        ) -> u32 {
            // SAFETY: the caller guarantees AVX-512 F; the rows are 64 bytes aligned to 64.
            unsafe {
                let load = |l: &Lanes| _mm512_load_ps(l.0.as_ptr());
                let rows = |r: &[Lanes; 3]| [load(&r[0]), load(&r[1]), load(&r[2])];
                let fused = Fused16 {
                    inv: rows(&rays.inv_dir),
                    inv_far: rows(&rays.inv_far),
                    near: rows(&self.0.near),
                    far: rows(&self.0.far),
                    t_min: load(&rays.t_min),
                    down: rays.down.map(|d| d as __mmask16),
                    rows: same_rows(rays, active),
                };
                children16(fused, node, rays, active, limit, out)
            }
        }

        #[inline(always)]
        unsafe fn within(self, dist: &Lanes, limit: &Lanes, active: u32) -> u32 {
            // SAFETY: the caller guarantees AVX-512 F.
            unsafe { within16(dist, limit, active) }
        }
    }
}

#[cfg(all(test, target_arch = "x86_64"))]
mod tests {
    use glam::Vec3;
    use rand::{RngExt, SeedableRng};
    use rand_pcg::Pcg32;

    use super::*;
    use crate::accel::wide::fused::child_entry_fused_scalar;
    use crate::accel::wide::isa::Isa;
    use crate::accel::wide::node::{WIDTH, WideNode, child_entry_scalar, reach};
    use crate::accel::wide::packet_kernels::{ChildHits, PacketKernel};
    use crate::{Aabb, Ray};

    fn has_avx512() -> bool {
        Isa::available().contains(&Isa::Avx512)
    }

    /// The bits of every lane of the constants.
    fn bits(p: &PacketPlanes) -> Vec<u32> {
        p.near.iter().chain(&p.far).flat_map(|l| l.0.map(f32::to_bits)).collect()
    }

    #[test]
    fn a_packets_constants_are_its_rays_own() {
        if !has_avx512() {
            return;
        }
        let mut rng = Pcg32::seed_from_u64(0xfa57_c0de);
        let (mut applied, mut refused) = (0, 0);
        for round in 0..20_000 {
            // Origins from near zero to far out, directions with tiny or zero components now and
            // then, starts below zero now and then: lanes the form applies to and lanes it does not.
            let scale = [1e-20f32, 1e-3, 1.0, 1e3, 1e25][round % 5];
            let mut unit = || rng.random::<f32>() * 2.0 - 1.0;
            let rays: Vec<Ray> = (0..1 + round % PACKET)
                .map(|i| {
                    let origin = Vec3::new(unit(), unit(), unit()) * scale;
                    let mut dir = Vec3::new(unit(), unit(), unit());
                    if (round + i) % 97 == 0 {
                        dir[i % 3] *= [0.0, 1e-36][i % 2];
                    }
                    let t_min = if (round + i) % 89 == 0 { -1.0 } else { 0.0 };
                    Ray::segment(origin, dir, t_min, f32::INFINITY)
                })
                .collect();
            let packet = PacketRays::new(&rays);
            let active = rng.random_range(1..1u32 << rays.len());
            let expected = PacketPlanes::new(&packet, active);
            // SAFETY: the processor has AVX-512 (checked above).
            let got = unsafe { PacketPlanes::new_avx512(&packet, active) };
            assert_eq!(got.as_ref().map(bits), expected.as_ref().map(bits), "lanes {active:b} of {rays:?}");
            applied += expected.is_some() as u32;
            refused += expected.is_none() as u32;
        }
        assert!(applied > 10_000 && refused > 1_000, "{applied} applied, {refused} refused");
    }

    /// The fused kernel on the packet, its lanes compared with each ray's fused test, bit for bit;
    /// a child it leaves out is entered by no ray's fused test, or culled by the interval, and
    /// then by no ray's exact-order test. Returns the rays entered and the children culled.
    fn check(node: &WideNode, rays: &[Ray], active: u32, bounded: bool) -> (u32, u32) {
        let mut packet = PacketRays::new(rays);
        if bounded {
            packet.bound(active);
        }
        let Some(planes) = PacketPlanes::new(&packet, active) else { return (0, 0) };
        let limit = Lanes(std::array::from_fn(|i| rays.get(i).map_or(0.0, |r| reach(r.t_max))));
        let mut got = ChildHits::NONE;
        // SAFETY: the caller checked that the processor has AVX-512.
        let mask = unsafe { Avx512FusedPacket(&planes).children(node, &packet, active, &limit, &mut got) };
        let (mut entered, mut culled) = (0, 0);
        for slot in 0..WIDTH {
            let (mut rays_in, mut exact_in) = (0u32, 0u32);
            let (mut near, mut exact_near) = (f32::INFINITY, f32::INFINITY);
            for (i, ray) in rays.iter().enumerate().filter(|&(i, _)| active >> i & 1 != 0) {
                let r = NodeRay::new(ray);
                let expected = child_entry_fused_scalar(node, slot, &r, &FusedPlanes::new(&r), limit.0[i]);
                if let Some(d) = expected {
                    rays_in |= 1 << i;
                    near = near.min(d);
                }
                if let Some(d) = child_entry_scalar(node, slot, &r, limit.0[i]) {
                    exact_in |= 1 << i;
                    exact_near = exact_near.min(d);
                }
                if mask >> slot & 1 != 0 {
                    let lane = got.dist[slot].0[i];
                    let got_lane = (!lane.is_nan()).then_some(lane);
                    assert_eq!(got_lane.map(f32::to_bits), expected.map(f32::to_bits), "slot {slot}, ray {i}");
                }
            }
            if mask >> slot & 1 != 0 {
                assert_eq!(got.rays[slot], rays_in, "rays of slot {slot}");
                if packet.interval.is_some() {
                    // The interval bounds the exact-order entries, which may lie a rounding
                    // beyond the fused ones: an order for the walk, not a distance.
                    assert!(got.near[slot] <= exact_near, "bound of the nearest entry of slot {slot}");
                } else {
                    assert_eq!(got.near[slot], near, "nearest entry of slot {slot}");
                }
            } else if rays_in != 0 {
                assert!(packet.interval.is_some() && exact_in == 0, "slot {slot} left out, entered by {rays_in:b}");
                culled += 1;
            }
            entered += rays_in.count_ones();
        }
        (entered, culled)
    }

    #[test]
    fn the_fused_packet_kernel_agrees_bit_for_bit_with_each_rays_fused_test() {
        if !has_avx512() {
            return;
        }
        // As the exact-order kernels' test (`packet_kernels`): integer planes and origins, so that
        // rays meet boxes at their corners and along their faces; no zero direction component
        // (the form does not apply to it); every other packet goes one way along each axis and
        // gets an interval. The scales move the planes and origins away from zero.
        let mut rng = Pcg32::seed_from_u64(0x0f05_ed16);
        let next = &mut move |n: u32| rng.random_range(0..n);
        fn point(next: &mut impl FnMut(u32) -> u32, v: &[f32]) -> Vec3 {
            let n = v.len() as u32;
            Vec3::new(v[next(n) as usize], v[next(n) as usize], v[next(n) as usize])
        }
        let values = [-2.0f32, -1.0, -0.0, 0.0, 0.5, 1.0, 2.0];
        let (mut entered, mut culled, mut bounded) = (0, 0, 0);
        for round in 0..8_000 {
            let scale = [1.0f32, 1e-3, 1e3, 1048576.0][round % 4];
            let offset = Vec3::splat([0.0, 4093.0][round / 4 % 2]) * scale;
            let mut node = WideNode::EMPTY_NODE;
            for slot in 0..1 + next(WIDTH as u32) as usize {
                let (a, b) = (point(next, &values) * scale + offset, point(next, &values) * scale + offset);
                node.set_child(slot, &Aabb::new(a.min(b), a.max(b)), slot as u32, 0);
            }
            let n = 1 + next(PACKET as u32) as usize;
            let one_way = round % 2 == 1;
            let signs = point(next, &[-1.0, 1.0]);
            let rays: Vec<Ray> = (0..n)
                .map(|_| {
                    let o = point(next, &values) * 1.5 * scale + offset;
                    let d = if one_way {
                        point(next, &[0.3, 0.5, 1.0]) * signs
                    } else {
                        point(next, &[-1.0, -0.3, 0.3, 1.0])
                    };
                    let t_min = [0.0, 0.0, 0.25][next(3) as usize] * scale;
                    Ray::segment(o, d, t_min, [f32::INFINITY, 1.0, 2.5][next(3) as usize] * scale)
                })
                .collect();
            let active = (next(1 << 16) | next(1 << 16) | 1) & ((1u32 << n) - 1);
            let (e, c) = check(&node, &rays, active, one_way);
            (entered, culled) = (entered + e, culled + c);
            bounded += (one_way && crate::accel::wide::packet_interval::PacketInterval::new(&rays).is_some()) as u32;
        }
        assert!(entered > 10_000 && bounded == 4_000, "{entered} entered, {bounded} bounded, {culled} culled");
    }
}
