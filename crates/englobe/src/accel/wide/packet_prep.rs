//! A packet's preparation with the instruction set of its query: the rays' rows made from the
//! caller's ([`RayPacket`]), their limits, the test of the packet against the tree's box and the
//! packet's interval ([`PacketInterval`]), all of it per ray before the first node.
//!
//! The portable preparation ([`Lanes4`]) works four lanes at a time through `glam`, which stays
//! four lanes wide whatever the processor has: four steps and four mask moves per row of sixteen
//! rays, and a minimum or maximum over a row of the interval in four pieces. With AVX-512 a row is
//! one register and a comparison lands in a mask register ([`Avx512Lanes`]); with AVX2 a row is
//! two, and a comparison's lanes become bits with one move per half ([`Avx2Lanes`]). (A plain
//! sixteen-lane loop left to the compiler was vectorised into pieces of two and four lanes, and
//! ran more instructions than `glam` in the AVX-512 copy.) Every way the same operations on the
//! same numbers, so the same bits, as the tests check lane by lane.

use super::packet_interval::PacketInterval;
use super::packet_rays::{Lanes, PacketRays};
use super::ray_packet::RayPacket;
use crate::Aabb;

/// How a packet query prepares its rays (see the module documentation).
pub trait PacketPrep: Copy {
    /// The rays of `rows` prepared for the walk, valid only in `active`, written into `p` (every
    /// field of it): [`RayPacket::prepare_into`].
    ///
    /// # Safety
    /// As [`super::kernels::NodeKernel::children`]: the caller is compiled with the
    /// preparation's target features and runs on a processor that has them.
    unsafe fn prepare_rows(self, rows: &RayPacket, active: u32, p: &mut PacketRays);

    /// How far each ray may enter a box: [`PacketRays::limits`].
    ///
    /// # Safety
    /// As [`PacketPrep::prepare_rows`].
    unsafe fn limits(self, p: &PacketRays) -> Lanes;

    /// The lanes that may enter `bounds` within `t_min..=limits[i]`: [`PacketRays::may_enter`].
    ///
    /// # Safety
    /// As [`PacketPrep::prepare_rows`].
    unsafe fn may_enter(self, p: &PacketRays, bounds: &Aabb, limits: &Lanes) -> u32;

    /// Adds the interval of the rays in `lanes` to `p`: [`PacketRays::bound`].
    ///
    /// # Safety
    /// As [`PacketPrep::prepare_rows`].
    unsafe fn bound(self, p: &mut PacketRays, lanes: u32);
}

/// Four lanes at a time through `glam`: every processor.
#[derive(Clone, Copy, Debug)]
pub struct Lanes4;

impl PacketPrep for Lanes4 {
    #[inline(always)]
    unsafe fn prepare_rows(self, rows: &RayPacket, active: u32, p: &mut PacketRays) {
        rows.prepare_into(active, p);
    }

    #[inline(always)]
    unsafe fn limits(self, p: &PacketRays) -> Lanes {
        p.limits()
    }

    #[inline(always)]
    unsafe fn may_enter(self, p: &PacketRays, bounds: &Aabb, limits: &Lanes) -> u32 {
        p.may_enter(bounds, limits)
    }

    #[inline(always)]
    unsafe fn bound(self, p: &mut PacketRays, lanes: u32) {
        p.bound(lanes);
    }
}

#[cfg(target_arch = "x86_64")]
pub use x86::{Avx2Lanes, Avx512Lanes};

#[cfg(target_arch = "x86_64")]
mod x86 {
    use std::arch::x86_64::*;

    use glam::Vec3A;

    use super::super::node::FAR_SCALE;
    use super::super::packet_rays::{PACKET, interval_axes};
    use super::{Aabb, Lanes, PacketInterval, PacketPrep, PacketRays, RayPacket};
    use crate::geom::aabb::ROBUST_FAR_SCALE;

    /// Sixteen lanes at once with AVX-512 F.
    #[derive(Clone, Copy, Debug)]
    pub struct Avx512Lanes;

    /// A row of sixteen floats (aligned to 64 bytes, as every row of a packet is).
    ///
    /// # Safety
    /// The caller is compiled with AVX-512 F and runs on a processor that has it.
    #[inline(always)]
    unsafe fn load(row: &[f32; PACKET]) -> __m512 {
        // SAFETY: the caller's guarantee; the rows of `RayPacket`, `Lanes` and `PacketRays` are
        // 64 bytes at offsets that are multiples of 64 in structures aligned to 64.
        unsafe { _mm512_load_ps(row.as_ptr()) }
    }

    /// Writes a row (aligned as in [`load`]).
    ///
    /// # Safety
    /// As [`load`].
    #[inline(always)]
    unsafe fn store(row: &mut [f32; PACKET], v: __m512) {
        // SAFETY: as in `load`.
        unsafe { _mm512_store_ps(row.as_mut_ptr(), v) }
    }

    /// The lanes whose value is finite (`|x| < inf`, as `glam`'s `is_finite_mask`).
    ///
    /// # Safety
    /// As [`load`].
    #[inline(always)]
    unsafe fn finite(x: __m512) -> __mmask16 {
        // SAFETY: as in `load`.
        unsafe { _mm512_cmp_ps_mask::<_CMP_LT_OQ>(_mm512_abs_ps(x), _mm512_set1_ps(f32::INFINITY)) }
    }

    impl PacketPrep for Avx512Lanes {
        #[inline(always)]
        unsafe fn prepare_rows(self, rows: &RayPacket, active: u32, p: &mut PacketRays) {
            // SAFETY (for the whole function): the caller's guarantee, and the rows as in `load`.
            unsafe {
                let zero = _mm512_setzero_ps();
                let (mut finite_lanes, mut moving) = (u16::MAX, 0);
                for a in 0..3 {
                    let (o, d) = (load(&rows.origin[a]), load(&rows.dir[a]));
                    // `Ray::segment`'s inverse: `+inf` for a zero of either sign.
                    let zero_d = _mm512_cmp_ps_mask::<_CMP_EQ_OQ>(d, zero);
                    let inv = _mm512_mask_blend_ps(
                        zero_d,
                        _mm512_div_ps(_mm512_set1_ps(1.0), d),
                        _mm512_set1_ps(f32::INFINITY),
                    );
                    store(&mut p.origin[a].0, o);
                    store(&mut p.dir[a].0, d);
                    store(&mut p.inv_dir[a].0, inv);
                    store(&mut p.inv_far[a].0, _mm512_mul_ps(inv, _mm512_set1_ps(FAR_SCALE)));
                    p.down[a] = _mm512_cmp_ps_mask::<_CMP_LT_OQ>(inv, zero) as u32;
                    finite_lanes &= finite(o) & finite(d);
                    // Unordered: a NaN component counts as moving, as `glam`'s `cmpne` has it
                    // (the ray is not valid either way: it is not finite).
                    moving |= _mm512_cmp_ps_mask::<_CMP_NEQ_UQ>(d, zero);
                }
                let (t_min, t_max) = (load(&rows.t_min), load(&rows.t_max));
                store(&mut p.t_min.0, t_min);
                store(&mut p.t_max.0, t_max);
                let nonempty = _mm512_cmp_ps_mask::<_CMP_LE_OQ>(t_min, t_max)
                    & _mm512_cmp_ps_mask::<_CMP_LT_OQ>(t_min, _mm512_set1_ps(f32::INFINITY))
                    & _mm512_cmp_ps_mask::<_CMP_GT_OQ>(t_max, _mm512_set1_ps(f32::NEG_INFINITY));
                p.valid = (finite_lanes & moving & nonempty) as u32 & active;
                p.interval = None;
            }
        }

        #[inline(always)]
        unsafe fn limits(self, p: &PacketRays) -> Lanes {
            // SAFETY: as in `prepare_rows`.
            unsafe {
                let t_max = load(&p.t_max.0);
                // A product then a sum, as `reach` rounds them (never fused).
                let stretch = _mm512_mul_ps(_mm512_abs_ps(t_max), _mm512_set1_ps(ROBUST_FAR_SCALE - 1.0));
                let mut limits = Lanes([0.0; PACKET]);
                store(&mut limits.0, _mm512_add_ps(t_max, stretch));
                limits
            }
        }

        #[inline(always)]
        unsafe fn may_enter(self, p: &PacketRays, bounds: &Aabb, limits: &Lanes) -> u32 {
            // SAFETY: as in `prepare_rows`.
            unsafe {
                let (mut enter, mut exit) = (load(&p.t_min.0), load(&limits.0));
                for a in 0..3 {
                    let (o, inv) = (load(&p.origin[a].0), load(&p.inv_dir[a].0));
                    let lo = _mm512_sub_ps(_mm512_set1_ps(bounds.min[a]), o);
                    let hi = _mm512_sub_ps(_mm512_set1_ps(bounds.max[a]), o);
                    let down = _mm512_cmp_ps_mask::<_CMP_LT_OQ>(inv, _mm512_setzero_ps());
                    let near = _mm512_mul_ps(_mm512_mask_blend_ps(down, lo, hi), inv);
                    let far = _mm512_mul_ps(_mm512_mask_blend_ps(down, hi, lo), load(&p.inv_far[a].0));
                    // `max(a, b)` is `a > b ? a : b`, `b` when either is NaN: a NaN distance
                    // constrains nothing, as in the portable test.
                    enter = _mm512_max_ps(near, enter);
                    exit = _mm512_min_ps(far, exit);
                }
                _mm512_cmp_ps_mask::<_CMP_LE_OQ>(enter, exit) as u32
            }
        }

        #[inline(always)]
        unsafe fn bound(self, p: &mut PacketRays, lanes: u32) {
            let Some(down) = interval_axes(p, lanes) else {
                p.interval = None;
                return;
            };
            // SAFETY: as in `prepare_rows`.
            unsafe {
                let k = lanes as __mmask16;
                let mut usable = k;
                let (mut o_lo, mut o_hi, mut inv_lo, mut inv_hi) = ([0.0; 3], [0.0; 3], [0.0; 3], [0.0; 3]);
                for a in 0..3 {
                    let (o, inv) = (load(&p.origin[a].0), load(&p.inv_dir[a].0));
                    usable &= finite(o) & finite(inv) & _mm512_cmp_ps_mask::<_CMP_NEQ_UQ>(inv, _mm512_setzero_ps());
                    // The lanes left out are passed over (taken as infinities of the right sign).
                    (o_lo[a], o_hi[a]) = (_mm512_mask_reduce_min_ps(k, o), _mm512_mask_reduce_max_ps(k, o));
                    (inv_lo[a], inv_hi[a]) = (_mm512_mask_reduce_min_ps(k, inv), _mm512_mask_reduce_max_ps(k, inv));
                }
                // Not `then` with a closure: its body would be compiled without AVX-512, and the
                // reduction in it made a call.
                p.interval = if usable == k {
                    let t_min = _mm512_mask_reduce_min_ps(k, load(&p.t_min.0));
                    Some(PacketInterval::from_bounds(
                        down,
                        [Vec3A::from_array(o_lo), Vec3A::from_array(o_hi)],
                        [Vec3A::from_array(inv_lo), Vec3A::from_array(inv_hi)],
                        t_min,
                    ))
                } else {
                    None
                };
            }
        }
    }

    /// Sixteen lanes in two halves of eight with AVX2 (and FMA's processors' AVX): comparisons
    /// into lane masks, moved into bits half by half.
    #[derive(Clone, Copy, Debug)]
    pub struct Avx2Lanes;

    /// Lanes of one half of a row.
    const HALF: usize = PACKET / 2;

    /// Half `h` of a row (aligned to 32 bytes: a 64-aligned row's first or second half).
    ///
    /// # Safety
    /// The caller is compiled with AVX and runs on a processor that has it.
    #[inline(always)]
    unsafe fn load8(row: &[f32; PACKET], h: usize) -> __m256 {
        // SAFETY: the caller's guarantee; `h` is 0 or 1 at every call, so the eight floats lie in
        // the row, at an offset of 0 or 32 bytes from its 64-aligned start.
        unsafe { _mm256_load_ps(row.as_ptr().add(HALF * h)) }
    }

    /// Writes half `h` of a row (aligned as in [`load8`]).
    ///
    /// # Safety
    /// As [`load8`].
    #[inline(always)]
    unsafe fn store8(row: &mut [f32; PACKET], h: usize, v: __m256) {
        // SAFETY: as in `load8`.
        unsafe { _mm256_store_ps(row.as_mut_ptr().add(HALF * h), v) }
    }

    /// The bits of the lanes a comparison set, in place for half `h`.
    ///
    /// # Safety
    /// As [`load8`].
    #[inline(always)]
    unsafe fn bits8(compared: __m256, h: usize) -> u32 {
        // SAFETY: as in `load8`.
        (unsafe { _mm256_movemask_ps(compared) } as u32) << (HALF * h)
    }

    /// The lanes of half `h` whose value is finite, as bits in place.
    ///
    /// # Safety
    /// As [`load8`].
    #[inline(always)]
    unsafe fn finite8(x: __m256, h: usize) -> u32 {
        // SAFETY: as in `load8`.
        unsafe {
            let magnitude = _mm256_andnot_ps(_mm256_set1_ps(-0.0), x);
            bits8(_mm256_cmp_ps::<_CMP_LT_OQ>(magnitude, _mm256_set1_ps(f32::INFINITY)), h)
        }
    }

    /// All ones in the lanes of half `h` whose bit is set in `lanes`.
    ///
    /// # Safety
    /// As [`load8`].
    #[inline(always)]
    unsafe fn taken8(lanes: u32, h: usize) -> __m256 {
        // SAFETY: as in `load8`.
        unsafe {
            let each = _mm256_setr_epi32(1, 2, 4, 8, 16, 32, 64, 128);
            let bits = _mm256_and_si256(_mm256_set1_epi32((lanes >> (HALF * h)) as i32), each);
            _mm256_castsi256_ps(_mm256_cmpeq_epi32(bits, each))
        }
    }

    /// `min` if `LEAST`, else `max` (`b` when either is NaN; the values here never are).
    ///
    /// # Safety
    /// As [`load8`].
    #[inline(always)]
    unsafe fn pick8<const LEAST: bool>(a: __m256, b: __m256) -> __m256 {
        // SAFETY: as in `load8`.
        unsafe { if LEAST { _mm256_min_ps(a, b) } else { _mm256_max_ps(a, b) } }
    }

    /// The least (`LEAST`) or the greatest of the lanes of `row` in `lanes`, the others passed
    /// over (taken as the infinity that loses). No closures: their bodies would be compiled
    /// without AVX, and every intrinsic in them made a call.
    ///
    /// # Safety
    /// As [`load8`].
    #[inline(always)]
    unsafe fn extreme8<const LEAST: bool>(row: &[f32; PACKET], lanes: u32) -> f32 {
        // SAFETY: as in `load8`.
        unsafe {
            let neutral = _mm256_set1_ps(if LEAST { f32::INFINITY } else { f32::NEG_INFINITY });
            let low = _mm256_blendv_ps(neutral, load8(row, 0), taken8(lanes, 0));
            let high = _mm256_blendv_ps(neutral, load8(row, 1), taken8(lanes, 1));
            let v = pick8::<LEAST>(low, high);
            let v = pick8::<LEAST>(v, _mm256_permute2f128_ps::<1>(v, v));
            let v = pick8::<LEAST>(v, _mm256_permute_ps::<0b01_00_11_10>(v));
            let v = pick8::<LEAST>(v, _mm256_permute_ps::<0b10_11_00_01>(v));
            _mm256_cvtss_f32(v)
        }
    }

    /// [`extreme8`] of each of the three `rows`.
    ///
    /// # Safety
    /// As [`load8`].
    #[inline(always)]
    unsafe fn extremes8<const LEAST: bool>(rows: &[Lanes; 3], lanes: u32) -> Vec3A {
        // SAFETY: as in `load8`.
        unsafe {
            Vec3A::new(
                extreme8::<LEAST>(&rows[0].0, lanes),
                extreme8::<LEAST>(&rows[1].0, lanes),
                extreme8::<LEAST>(&rows[2].0, lanes),
            )
        }
    }

    impl PacketPrep for Avx2Lanes {
        #[inline(always)]
        unsafe fn prepare_rows(self, rows: &RayPacket, active: u32, p: &mut PacketRays) {
            // SAFETY (for the whole function): the caller's guarantee, and the rows as in `load8`.
            unsafe {
                let (zero, inf) = (_mm256_setzero_ps(), _mm256_set1_ps(f32::INFINITY));
                p.down = [0; 3];
                p.valid = 0;
                for h in 0..2 {
                    let (mut finite_lanes, mut moving) = (u32::MAX, 0);
                    for a in 0..3 {
                        let (o, d) = (load8(&rows.origin[a], h), load8(&rows.dir[a], h));
                        // `Ray::segment`'s inverse: `+inf` for a zero of either sign.
                        let zero_d = _mm256_cmp_ps::<_CMP_EQ_OQ>(d, zero);
                        let inv = _mm256_blendv_ps(_mm256_div_ps(_mm256_set1_ps(1.0), d), inf, zero_d);
                        store8(&mut p.origin[a].0, h, o);
                        store8(&mut p.dir[a].0, h, d);
                        store8(&mut p.inv_dir[a].0, h, inv);
                        store8(&mut p.inv_far[a].0, h, _mm256_mul_ps(inv, _mm256_set1_ps(FAR_SCALE)));
                        p.down[a] |= bits8(_mm256_cmp_ps::<_CMP_LT_OQ>(inv, zero), h);
                        finite_lanes &= finite8(o, h) & finite8(d, h);
                        // Unordered, as in the AVX-512 preparation.
                        moving |= bits8(_mm256_cmp_ps::<_CMP_NEQ_UQ>(d, zero), h);
                    }
                    let (t_min, t_max) = (load8(&rows.t_min, h), load8(&rows.t_max, h));
                    store8(&mut p.t_min.0, h, t_min);
                    store8(&mut p.t_max.0, h, t_max);
                    let nonempty = _mm256_and_ps(
                        _mm256_cmp_ps::<_CMP_LE_OQ>(t_min, t_max),
                        _mm256_and_ps(
                            _mm256_cmp_ps::<_CMP_LT_OQ>(t_min, inf),
                            _mm256_cmp_ps::<_CMP_GT_OQ>(t_max, _mm256_set1_ps(f32::NEG_INFINITY)),
                        ),
                    );
                    p.valid |= finite_lanes & moving & bits8(nonempty, h);
                }
                p.valid &= active;
                p.interval = None;
            }
        }

        #[inline(always)]
        unsafe fn limits(self, p: &PacketRays) -> Lanes {
            // SAFETY: as in `prepare_rows`.
            unsafe {
                let mut limits = Lanes([0.0; PACKET]);
                for h in 0..2 {
                    let t_max = load8(&p.t_max.0, h);
                    let magnitude = _mm256_andnot_ps(_mm256_set1_ps(-0.0), t_max);
                    // A product then a sum, as `reach` rounds them (never fused).
                    let stretch = _mm256_mul_ps(magnitude, _mm256_set1_ps(ROBUST_FAR_SCALE - 1.0));
                    store8(&mut limits.0, h, _mm256_add_ps(t_max, stretch));
                }
                limits
            }
        }

        #[inline(always)]
        unsafe fn may_enter(self, p: &PacketRays, bounds: &Aabb, limits: &Lanes) -> u32 {
            // SAFETY: as in `prepare_rows`.
            unsafe {
                let mut mask = 0;
                for h in 0..2 {
                    let (mut enter, mut exit) = (load8(&p.t_min.0, h), load8(&limits.0, h));
                    for a in 0..3 {
                        let (o, inv) = (load8(&p.origin[a].0, h), load8(&p.inv_dir[a].0, h));
                        let lo = _mm256_sub_ps(_mm256_set1_ps(bounds.min[a]), o);
                        let hi = _mm256_sub_ps(_mm256_set1_ps(bounds.max[a]), o);
                        let down = _mm256_cmp_ps::<_CMP_LT_OQ>(inv, _mm256_setzero_ps());
                        let near = _mm256_mul_ps(_mm256_blendv_ps(lo, hi, down), inv);
                        let far = _mm256_mul_ps(_mm256_blendv_ps(hi, lo, down), load8(&p.inv_far[a].0, h));
                        // As in the AVX-512 test: a NaN distance constrains nothing.
                        enter = _mm256_max_ps(near, enter);
                        exit = _mm256_min_ps(far, exit);
                    }
                    mask |= bits8(_mm256_cmp_ps::<_CMP_LE_OQ>(enter, exit), h);
                }
                mask
            }
        }

        #[inline(always)]
        unsafe fn bound(self, p: &mut PacketRays, lanes: u32) {
            let Some(down) = interval_axes(p, lanes) else {
                p.interval = None;
                return;
            };
            // SAFETY: as in `prepare_rows`.
            unsafe {
                let mut usable = 0;
                for h in 0..2 {
                    // Each half's bits in place, the other half's clear.
                    let mut half = u32::MAX;
                    for a in 0..3 {
                        let (o, inv) = (load8(&p.origin[a].0, h), load8(&p.inv_dir[a].0, h));
                        let nonzero = _mm256_cmp_ps::<_CMP_NEQ_UQ>(inv, _mm256_setzero_ps());
                        half &= finite8(o, h) & finite8(inv, h) & bits8(nonzero, h);
                    }
                    usable |= half;
                }
                if usable & lanes != lanes {
                    p.interval = None;
                    return;
                }
                let (o, inv) = (&p.origin, &p.inv_dir);
                let interval = PacketInterval::from_bounds(
                    down,
                    [extremes8::<true>(o, lanes), extremes8::<false>(o, lanes)],
                    [extremes8::<true>(inv, lanes), extremes8::<false>(inv, lanes)],
                    extreme8::<true>(&p.t_min.0, lanes),
                );
                p.interval = Some(interval);
            }
        }
    }
}

#[cfg(all(test, target_arch = "x86_64"))]
mod tests {
    use glam::Vec3;
    use rand::{RngExt, SeedableRng};
    use rand_pcg::Pcg32;

    use super::super::isa::Isa;
    use super::super::packet_rays::PACKET;
    use super::*;
    use crate::Ray;

    /// The bits of a row.
    fn bits(l: &Lanes) -> [u32; PACKET] {
        l.0.map(f32::to_bits)
    }

    /// Both preparations of random packets, with coordinates now and then replaced by zeros of
    /// both signs, infinities, NaN and tiny numbers, give the same bits in every field, limit,
    /// box test and interval.
    #[test]
    fn sixteen_lanes_at_once_prepare_as_four_at_a_time() {
        if Isa::Avx512.is_available() {
            agree_with_four_lanes(Avx512Lanes);
        }
        if Isa::Avx2.is_available() {
            agree_with_four_lanes(Avx2Lanes);
        }
    }

    /// `prep` against the four-lane preparation (its instruction set available).
    fn agree_with_four_lanes(prep: impl PacketPrep + std::fmt::Debug) {
        let mut rng = Pcg32::seed_from_u64(0x16_1a4e5);
        let odd = [0.0f32, -0.0, f32::INFINITY, f32::NEG_INFINITY, f32::NAN, 1e-40, -3.5];
        let (mut valid, mut entered, mut intervals) = (0, 0, 0);
        for round in 0..3_000 {
            let mut rows = RayPacket::default();
            // Every fourth packet a camera's: one direction sign per axis, so that it has an
            // interval; the others anything.
            let camera = round % 4 == 0;
            for lane in 0..PACKET {
                let mut r = [0.0f32; 6];
                for x in &mut r {
                    *x = rng.random_range(-1.0..1.0);
                }
                let mut v = |x: f32| {
                    if !camera && rng.random_range(0..6) == 0 { odd[rng.random_range(0..odd.len())] } else { x }
                };
                let o = Vec3::new(v(2.0 * r[0]), v(0.5), v(r[1]));
                let d = Vec3::new(v(0.1 + r[2].abs()), v(-1.0), v(r[3]));
                let d = if camera { d.abs() * Vec3::new(1.0, -1.0, 1.0) } else { d };
                let (t_min, t_max) = (v(0.0), v(10.0 + 9.0 * r[4]));
                rows.set(lane, o, d, t_min, t_max);
            }
            let active = rng.random_range(0..=u16::MAX as u32);
            // Into packets that hold other rays, an interval included: every field is written.
            let other = PacketRays::new(&[Ray::new(Vec3::splat(3.0), Vec3::new(-1.0, -2.0, -0.5)); PACKET]);
            let (mut four, mut sixteen) = (other, other);
            sixteen.bound(u32::MAX >> (32 - PACKET));
            assert!(sixteen.interval.is_some());
            // SAFETY: `prep`'s instruction set is available (the caller checks); the portable one
            // needs nothing.
            unsafe {
                Lanes4.prepare_rows(&rows, active, &mut four);
                prep.prepare_rows(&rows, active, &mut sixteen);
            }
            for a in 0..3 {
                assert_eq!(bits(&four.origin[a]), bits(&sixteen.origin[a]));
                assert_eq!(bits(&four.dir[a]), bits(&sixteen.dir[a]));
                assert_eq!(bits(&four.inv_dir[a]), bits(&sixteen.inv_dir[a]), "{rows:?}");
                assert_eq!(bits(&four.inv_far[a]), bits(&sixteen.inv_far[a]));
                assert_eq!(four.down[a], sixteen.down[a]);
            }
            assert_eq!((bits(&four.t_min), bits(&four.t_max)), (bits(&sixteen.t_min), bits(&sixteen.t_max)));
            assert_eq!(four.valid, sixteen.valid, "{rows:?}");
            assert_eq!(sixteen.interval, None);
            valid += four.valid.count_ones();

            // SAFETY: as above.
            let (limits, limits16) = unsafe { (Lanes4.limits(&four), prep.limits(&four)) };
            assert_eq!(bits(&limits), bits(&limits16));
            let (a, b) = (
                Vec3::new(rng.random_range(-3.0..1.0), rng.random_range(-3.0..0.0), rng.random_range(-2.0..1.0)),
                Vec3::new(rng.random_range(1.0..4.0), rng.random_range(-1.0..2.0), rng.random_range(0.0..3.0)),
            );
            // Now and then a flat box, or one whose planes the origins lie on.
            let bounds = match round % 5 {
                0 => Aabb::new(a, Vec3::new(b.x, a.y, b.z)),
                1 => Aabb::new(Vec3::new(-2.0, 0.5, a.z), b),
                _ => Aabb::new(a, b),
            };
            // SAFETY: as above.
            let mask = unsafe { Lanes4.may_enter(&four, &bounds, &limits) };
            assert_eq!(mask, unsafe { prep.may_enter(&four, &bounds, &limits) }, "{prep:?}: {rows:?}, {bounds:?}");
            entered += (mask & four.valid).count_ones();

            let lanes = four.valid & rng.random_range(0..=u16::MAX as u32);
            let mut bounded = four;
            // SAFETY: as above.
            unsafe {
                Lanes4.bound(&mut four, lanes);
                prep.bound(&mut bounded, lanes);
            }
            assert_eq!(four.interval, bounded.interval, "lanes {lanes:b} of {rows:?}");
            intervals += four.interval.is_some() as u32;
        }
        assert!(valid > 10_000 && entered > 5_000 && intervals > 300, "{valid}, {entered}, {intervals}");
    }
}
