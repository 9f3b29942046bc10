//! The watertight triangle test (Woop, Benthin and Wald 2013) of one triangle against a whole
//! packet at once: sixteen rays in the lanes of an AVX-512 vector (or of two AVX2 vectors), the
//! triangle's coordinates broadcast, as Embree's hybrid traversal tests its `Triangle4` leaves
//! against ray packets (Wald et al. 2014). The test shears each ray's frame by its own axes; a
//! packet whose rays share the axes (the camera rays of a tile, nearly always) reads the same
//! rows of the block for every lane, so only those packets take this path. The others are asked
//! again one ray at a time (see `triangle_packet_leaves`).
//!
//! Each lane computes exactly what a lane of the single-ray block test
//! ([`super::triangles::intersect_block`]) computes for its ray and triangle: the same arithmetic
//! in the same order (but for the AVX-512 projection's differences, taken the other way round:
//! exactly their negations, which change no value after them), no fused multiply-add, the same
//! *special* cases left to the scalar test (found, with AVX-512, by one class test per value where
//! the block test compares magnitudes: the same lanes). So every ray keeps the answer of its own
//! query, as `englobe/tests/packet_blocks.rs` checks bit for bit.

use super::packet_kernels::{Lanes, PACKET, PacketRays};
#[cfg(target_arch = "x86_64")]
use super::triangles::TriBlock;
use crate::Vec3;
use crate::accel::Hit;
use crate::shapes::WatertightRay;

/// A packet whose rays share the watertight test's axes, prepared for triangle tests: what the
/// constants of [`super::triangles::TriRay`] add to the packet's [`PacketRays`] (which holds the
/// origins, inverse directions and `t_min`), as a structure of arrays.
#[derive(Clone, Copy, Debug)]
#[repr(C, align(64))]
pub struct PacketTriRays {
    /// The origins' coordinates on the axes `kx`, `ky`, `kz`.
    origin_k: [Lanes; 3],
    /// The shears `(d[kx] / d[kz], d[ky] / d[kz], 1 / d[kz])`.
    shear: [Lanes; 3],
    axes: [usize; 3],
}

impl PacketTriRays {
    /// The watertight test's axes `[kx, ky, kz]` of the rays of `active` (bit per ray of
    /// `packet`, at least one), or `None` if they do not all share them.
    #[inline(always)]
    pub fn shared_axes(packet: &PacketRays, active: u32) -> Option<[usize; 3]> {
        if active == 0 {
            return None;
        }
        // Each lane's axes, as `WatertightRay::axes_of` chooses them, in one small integer (the
        // axis of the largest component and whether the ray goes down it): every lane at once in
        // one vector loop, since this runs for every packet before its walk.
        let [dx, dy, dz] = [&packet.dir[0].0, &packet.dir[1].0, &packet.dir[2].0];
        let mut code = [0u32; PACKET];
        for i in 0..PACKET {
            let (ax, ay, az) = (dx[i].abs(), dy[i].abs(), dz[i].abs());
            let x_largest = (ax >= ay) & (ax >= az);
            let y_largest = !x_largest & (ay >= az);
            let d = if x_largest {
                dx[i]
            } else if y_largest {
                dy[i]
            } else {
                dz[i]
            };
            code[i] = 2 * (!x_largest as u32 + !(x_largest | y_largest) as u32) + (d < 0.0) as u32;
        }
        let first = active.trailing_zeros() as usize;
        let mut differ = 0u32;
        for (i, &c) in code.iter().enumerate() {
            differ |= ((c != code[first]) as u32) << i;
        }
        if differ & active != 0 {
            return None;
        }
        Some(WatertightRay::axes_of(Vec3::new(dx[first], dy[first], dz[first])))
    }

    /// Prepares the rays of `active` (bit per ray of `packet`), which share the axes `axes`
    /// ([`PacketTriRays::shared_axes`]).
    #[inline(always)]
    pub fn new(packet: &PacketRays, active: u32, axes: [usize; 3]) -> Self {
        // The rows of the shared axes, whole: the lanes left out are never read but for the
        // divisions below, where 1 along `kz` keeps them finite.
        let mut p = PacketTriRays { origin_k: axes.map(|a| packet.origin[a]), shear: [Lanes([0.0; PACKET]); 3], axes };
        let [dx, dy, mut dz] = axes.map(|a| packet.dir[a].0);
        for (i, dz) in dz.iter_mut().enumerate() {
            if active >> i & 1 == 0 {
                *dz = 1.0;
            }
        }
        // The shear of `WatertightRay::new`, the same divisions lane by lane (one vector loop).
        for i in 0..PACKET {
            p.shear[0].0[i] = dx[i] / dz[i];
            p.shear[1].0[i] = dy[i] / dz[i];
            p.shear[2].0[i] = 1.0 / dz[i];
        }
        p
    }
}

/// The closest hit of each ray of a packet so far, as a structure of arrays. A ray without a hit
/// has `prim` [`u32::MAX`] and `t` its `t_max`.
#[derive(Clone, Copy, Debug)]
#[repr(C, align(64))]
pub struct PacketBest {
    /// Distances: of the hit, or the ray's `t_max`.
    pub t: Lanes,
    /// First barycentric.
    pub u: Lanes,
    /// Second barycentric.
    pub v: Lanes,
    /// Triangle indices (as the bits of floats, so that the whole record moves in vectors).
    pub prim: Lanes,
}

impl PacketBest {
    /// No hit yet, each ray's interval ending at its `t_max` (the packet's [`PacketRays::t_max`]).
    pub fn new(t_max: &Lanes) -> Self {
        let none = Lanes([f32::from_bits(u32::MAX); PACKET]);
        PacketBest { t: *t_max, u: Lanes([0.0; PACKET]), v: Lanes([0.0; PACKET]), prim: none }
    }

    /// The triangle ray `i` hits, if any.
    #[inline(always)]
    pub fn prim(&self, i: usize) -> u32 {
        self.prim.0[i].to_bits()
    }

    /// The closest hit of ray `i`.
    #[inline(always)]
    pub fn hit(&self, i: usize) -> Option<Hit> {
        (self.prim(i) != u32::MAX).then(|| Hit { t: self.t.0[i], prim: self.prim(i), u: self.u.0[i], v: self.v.0[i] })
    }

    /// Keeps `hit` as ray `i`'s closest if it is closer, or as close with a lower index (the rule
    /// of [`crate::accel::HitRecord::offer`]).
    #[inline(always)]
    pub fn offer(&mut self, i: usize, hit: Hit) {
        if hit.t < self.t.0[i] || (hit.t == self.t.0[i] && hit.prim < self.prim(i)) {
            (self.t.0[i], self.u.0[i], self.v.0[i], self.prim.0[i]) = (hit.t, hit.u, hit.v, f32::from_bits(hit.prim));
        }
    }
}

/// The whole-packet test of one block, compiled for one instruction set ([`Avx512Block`] or
/// [`Avx2Block`]): what a packet walk compiled for that set tests its leaves with.
#[cfg(target_arch = "x86_64")]
pub trait BlockTest: Copy {
    /// Rays at most for which a leaf is tested ray by ray instead, with the single-ray block
    /// test (see `triangle_packet_leaves`).
    const ALONE: u32;

    /// Tests the rays of `rays` against every used triangle of `block`, as
    /// [`block_avx512`] does.
    ///
    /// # Safety
    /// The processor has the test's instruction set, and the caller should be compiled with it.
    unsafe fn block(
        block: &TriBlock,
        packet: &PacketRays,
        r: &PacketTriRays,
        rays: u32,
        best: &mut PacketBest,
        closest: bool,
    ) -> (u32, u64);

    /// [`PacketTriRays::shared_axes`], with the test's instruction set.
    ///
    /// # Safety
    /// As [`BlockTest::block`].
    #[inline(always)]
    unsafe fn shared_axes(packet: &PacketRays, active: u32) -> Option<[usize; 3]> {
        PacketTriRays::shared_axes(packet, active)
    }
}

/// The test with AVX-512: the sixteen rays in one vector.
#[cfg(target_arch = "x86_64")]
#[derive(Clone, Copy, Debug)]
pub struct Avx512Block;

/// [`BlockTest::ALONE`] of [`Avx2Block`].
#[cfg(target_arch = "x86_64")]
const ALONE_AVX2: u32 = 3;

/// The test with AVX2: the sixteen rays in two vectors of eight.
#[cfg(target_arch = "x86_64")]
#[derive(Clone, Copy, Debug)]
pub struct Avx2Block;

#[cfg(target_arch = "x86_64")]
impl BlockTest for Avx512Block {
    const ALONE: u32 = 0;

    #[inline(always)]
    unsafe fn block(
        block: &TriBlock,
        packet: &PacketRays,
        r: &PacketTriRays,
        rays: u32,
        best: &mut PacketBest,
        closest: bool,
    ) -> (u32, u64) {
        // SAFETY: the caller's guarantee: AVX-512.
        unsafe { block_avx512(block, packet, r, rays, best, closest) }
    }

    #[inline(always)]
    unsafe fn shared_axes(packet: &PacketRays, active: u32) -> Option<[usize; 3]> {
        // SAFETY: the caller's guarantee: AVX-512.
        unsafe { shared_axes_avx512(packet, active) }
    }
}

#[cfg(target_arch = "x86_64")]
impl BlockTest for Avx2Block {
    const ALONE: u32 = ALONE_AVX2;

    #[inline(always)]
    unsafe fn block(
        block: &TriBlock,
        packet: &PacketRays,
        r: &PacketTriRays,
        rays: u32,
        best: &mut PacketBest,
        closest: bool,
    ) -> (u32, u64) {
        // SAFETY: the caller's guarantee: AVX2.
        unsafe { block_avx2(block, packet, r, rays, best, closest) }
    }
}

#[cfg(target_arch = "x86_64")]
pub use x86::{block_avx2, block_avx512, shared_axes_avx512};

#[cfg(target_arch = "x86_64")]
mod x86 {
    use std::arch::x86_64::*;

    use super::super::triangles::{LANES, TriBlock, UNUSED};
    use super::{PacketBest, PacketRays, PacketTriRays};
    use crate::Vec3;
    use crate::geom::aabb::ROBUST_FAR_SCALE;
    use crate::shapes::WatertightRay;

    /// [`PacketTriRays::shared_axes`] sixteen lanes at once: each lane's largest direction
    /// component (the first of equal ones, in the order x, y, z) and its sign as masks, the same
    /// comparisons as the portable form's (a NaN compares false in both).
    ///
    /// # Safety
    /// The processor has AVX-512 F; the caller should be compiled with it.
    #[inline(always)]
    pub unsafe fn shared_axes_avx512(packet: &PacketRays, active: u32) -> Option<[usize; 3]> {
        if active == 0 {
            return None;
        }
        // SAFETY: the caller's guarantee; the rows are 64 bytes aligned to 64.
        unsafe {
            // No `map` over arrays: it compiled to a call.
            let load = |a: usize| _mm512_load_ps(packet.dir[a].0.as_ptr());
            let (dx, dy, dz) = (load(0), load(1), load(2));
            let (ax, ay, az) = (_mm512_abs_ps(dx), _mm512_abs_ps(dy), _mm512_abs_ps(dz));
            let ge = |a: __m512, b: __m512| _mm512_cmp_ps_mask::<_CMP_GE_OQ>(a, b);
            let below = |v: __m512| _mm512_cmp_ps_mask::<_CMP_LT_OQ>(v, _mm512_setzero_ps());
            let x_largest = ge(ax, ay) & ge(ax, az);
            let y_largest = !x_largest & ge(ay, az);
            let z_largest = !(x_largest | y_largest);
            let down = (x_largest & below(dx)) | (y_largest & below(dy)) | (z_largest & below(dz));
            // Every active lane as the first: each mask all set or all clear over them.
            let (lanes, first) = (active as u16, active.trailing_zeros() as usize);
            let same = |m: u16| m & lanes == 0 || m & lanes == lanes;
            if !(same(x_largest) && same(y_largest) && same(down)) {
                return None;
            }
            let at = |a: usize| packet.dir[a].0[first];
            Some(WatertightRay::axes_of(Vec3::new(at(0), at(1), at(2))))
        }
    }

    /// Tests the rays of `rays` (bits of the packet `packet`, whose shared-axes constants are
    /// `r`) against every used triangle of `block`. With `closest`, keeps each ray's closest hit
    /// in `best` (closer, or as close with a lower index, as [`crate::accel::HitRecord::offer`]);
    /// without, only reports hits within `best.t`. Returns
    /// the rays that hit, and the pairs the scalar test must decide (bit `16 * lane + ray`).
    ///
    /// Compiled into its caller (`#[inline(always)]`, without features of its own), so that a
    /// packet walk compiled with AVX-512 keeps its registers across it: a call in the walk's loop
    /// would have the caller save every vector register.
    ///
    /// # Safety
    /// The processor has AVX-512 F, VL, BW and DQ. The caller should be compiled with them, or
    /// every intrinsic below becomes a call.
    #[inline(always)]
    pub unsafe fn block_avx512(
        block: &TriBlock,
        packet: &PacketRays,
        r: &PacketTriRays,
        rays: u32,
        best: &mut PacketBest,
        closest: bool,
    ) -> (u32, u64) {
        // SAFETY: the caller's guarantee: the processor has the features of every intrinsic.
        unsafe {
            let rays = rays as __mmask16;
            // Aligned loads and stores: every `Lanes` is 64 bytes aligned to 64.
            let load = |l: &super::Lanes| _mm512_load_ps(l.0.as_ptr());
            let [kx, ky, kz] = r.axes;
            let o_k = [load(&r.origin_k[0]), load(&r.origin_k[1]), load(&r.origin_k[2])];
            let (sx, sy) = (load(&r.shear[0]), load(&r.shear[1]));
            let neg_sz = _mm512_castsi512_ps(_mm512_xor_si512(
                _mm512_castps_si512(load(&r.shear[2])),
                _mm512_set1_epi32(i32::MIN),
            ));
            let zero = _mm512_setzero_ps();
            // The lanes holding a normal number, or a finite one, each class test one `vfpclassps`
            // (the same lanes as `MIN_POSITIVE <= |x| < inf` and `|x| < inf`): its categories are
            // quiet NaN 0x01, +0 0x02, -0 0x04, +inf 0x08, -inf 0x10, subnormal 0x20 and
            // signalling NaN 0x80.
            let normal = |x: __m512| !_mm512_fpclass_ps_mask::<0xbf>(x);
            let finite = |x: __m512| !_mm512_fpclass_ps_mask::<0x99>(x);
            let (mut hit_rays, mut special_pairs) = (0u16, 0u64);
            // The four triangles' boxes, made at the block's first candidate lane (most blocks
            // have none) for all four at once, as the block test makes them: `min` and `max` of
            // the three vertices' rows, in its order.
            let (mut lows, mut highs, mut boxes_made) = ([[0.0f32; LANES]; 3], [[0.0f32; LANES]; 3], false);
            // The rays' rows the correction reads, and the lanes going up each axis, once per block.
            let inv = [load(&packet.inv_dir[0]), load(&packet.inv_dir[1]), load(&packet.inv_dir[2])];
            let origin = [load(&packet.origin[0]), load(&packet.origin[1]), load(&packet.origin[2])];
            let going_up = |inv: __m512| _mm512_cmp_ps_mask::<_CMP_GE_OQ>(inv, zero);
            let up = [going_up(inv[0]), going_up(inv[1]), going_up(inv[2])];
            for lane in 0..LANES {
                let id = block.ids[lane];
                if id == UNUSED {
                    continue;
                }
                let at = |k: usize, axis: usize| block.v[3 * k + axis][lane];
                // Vertex k relative to the origin, sheared: the block test's `ax`, `ay`, `az`,
                // negated. Each difference is taken the other way round, `o - v`, so that the
                // vertex is the value subtracted and its broadcast folds into the subtraction;
                // rounding to nearest is symmetric, so every value is exactly the negation of the
                // block test's, the edge functions (products of two of them) are its own bit for
                // bit, and `az`, `bz`, `cz` are too, with the shear's `sz` negated (`neg_sz`).
                // A macro rather than a closure: the closure, called three times, stayed a call.
                macro_rules! project {
                    ($k:expr) => {{
                        let x = _mm512_sub_ps(o_k[0], _mm512_set1_ps(at($k, kx)));
                        let y = _mm512_sub_ps(o_k[1], _mm512_set1_ps(at($k, ky)));
                        let z = _mm512_sub_ps(o_k[2], _mm512_set1_ps(at($k, kz)));
                        (_mm512_sub_ps(x, _mm512_mul_ps(sx, z)), _mm512_sub_ps(y, _mm512_mul_ps(sy, z)), z)
                    }};
                }
                let (ax, ay, a_z) = project!(0);
                let (bx, by, b_z) = project!(1);
                let (cx, cy, c_z) = project!(2);
                let e0 = _mm512_sub_ps(_mm512_mul_ps(cx, by), _mm512_mul_ps(cy, bx));
                let e1 = _mm512_sub_ps(_mm512_mul_ps(ax, cy), _mm512_mul_ps(ay, cx));
                let e2 = _mm512_sub_ps(_mm512_mul_ps(bx, ay), _mm512_mul_ps(by, ax));
                let lt = |e| _mm512_cmp_ps_mask::<_CMP_LT_OQ>(e, zero);
                let gt = |e| _mm512_cmp_ps_mask::<_CMP_GT_OQ>(e, zero);
                let negative = lt(e0) | lt(e1) | lt(e2);
                let positive = gt(e0) | gt(e1) | gt(e2);
                let inside = !(negative & positive) & rays;
                if inside == 0 {
                    continue;
                }
                let all_normal = normal(e0) & normal(e1) & normal(e2);
                let mut special = inside & !all_normal;
                let candidate = inside & all_normal;
                if candidate != 0 {
                    let (az, bz, cz) =
                        (_mm512_mul_ps(neg_sz, a_z), _mm512_mul_ps(neg_sz, b_z), _mm512_mul_ps(neg_sz, c_z));
                    let det = _mm512_add_ps(_mm512_add_ps(e0, e1), e2);
                    let t_scaled = _mm512_add_ps(
                        _mm512_add_ps(_mm512_mul_ps(e0, az), _mm512_mul_ps(e1, bz)),
                        _mm512_mul_ps(e2, cz),
                    );
                    let inv_det = _mm512_div_ps(_mm512_set1_ps(1.0), det);
                    let t = _mm512_mul_ps(t_scaled, inv_det);
                    let t_finite = finite(t);
                    special |= candidate & !t_finite;
                    let candidate = candidate & t_finite;
                    // The box-stretch correction, as the block test computes it.
                    if !boxes_made {
                        for axis in 0..3 {
                            // The block's rows are 16 bytes aligned to 16.
                            let row = |k: usize| _mm_load_ps(block.v[3 * k + axis].as_ptr());
                            let (p, q, s) = (row(0), row(1), row(2));
                            _mm_storeu_ps(lows[axis].as_mut_ptr(), _mm_min_ps(_mm_min_ps(p, q), s));
                            _mm_storeu_ps(highs[axis].as_mut_ptr(), _mm_max_ps(_mm_max_ps(p, q), s));
                        }
                        boxes_made = true;
                    }
                    let (mut enter, mut exit) = (_mm512_set1_ps(f32::NEG_INFINITY), _mm512_set1_ps(f32::INFINITY));
                    for axis in 0..3 {
                        let (lo, hi) = (_mm512_set1_ps(lows[axis][lane]), _mm512_set1_ps(highs[axis][lane]));
                        let (inv, o) = (inv[axis], origin[axis]);
                        let near = _mm512_mask_blend_ps(up[axis], hi, lo);
                        let far = _mm512_mask_blend_ps(up[axis], lo, hi);
                        let t_near = _mm512_mul_ps(_mm512_sub_ps(near, o), inv);
                        let t_far =
                            _mm512_mul_ps(_mm512_mul_ps(_mm512_sub_ps(far, o), inv), _mm512_set1_ps(ROBUST_FAR_SCALE));
                        // `max(a, b)` is `a > b ? a : b`: the block test's `keep_greater`.
                        enter = _mm512_max_ps(t_near, enter);
                        exit = _mm512_min_ps(t_far, exit);
                    }
                    let in_box = _mm512_cmp_ps_mask::<_CMP_LE_OQ>(enter, exit);
                    let t = _mm512_mask_blend_ps(_mm512_cmp_ps_mask::<_CMP_LT_OQ>(t, enter), t, enter);
                    let t = _mm512_mask_blend_ps(_mm512_cmp_ps_mask::<_CMP_GT_OQ>(t, exit), t, exit);
                    let best_t = load(&best.t);
                    let in_range = _mm512_cmp_ps_mask::<_CMP_GE_OQ>(t, load(&packet.t_min))
                        & _mm512_cmp_ps_mask::<_CMP_LE_OQ>(t, best_t);
                    let hit = candidate & in_box & in_range;
                    hit_rays |= hit;
                    if closest && hit != 0 {
                        let prim = _mm512_set1_epi32(id as i32);
                        let best_prim = _mm512_castps_si512(load(&best.prim));
                        let better = hit
                            & (_mm512_cmp_ps_mask::<_CMP_LT_OQ>(t, best_t)
                                | (_mm512_cmp_ps_mask::<_CMP_EQ_OQ>(t, best_t)
                                    & _mm512_cmplt_epu32_mask(prim, best_prim)));
                        let store = |l: &mut super::Lanes, x: __m512| {
                            _mm512_store_ps(l.0.as_mut_ptr(), _mm512_mask_blend_ps(better, load(l), x))
                        };
                        store(&mut best.t, t);
                        store(&mut best.u, _mm512_mul_ps(e1, inv_det));
                        store(&mut best.v, _mm512_mul_ps(e2, inv_det));
                        store(&mut best.prim, _mm512_castsi512_ps(prim));
                    }
                }
                special_pairs |= (special as u64) << (16 * lane);
            }
            (hit_rays as u32, special_pairs)
        }
    }

    /// [`block_avx512`] with AVX2: the packet's sixteen lanes as two vectors of eight, each
    /// computing what the AVX-512 test computes in those lanes (the same operations in the same
    /// order; a mask register's blend is a blend by a comparison's lanes here).
    ///
    /// # Safety
    /// The processor has AVX2. The caller should be compiled with it, or every intrinsic below
    /// becomes a call.
    #[inline(always)]
    pub unsafe fn block_avx2(
        block: &TriBlock,
        packet: &PacketRays,
        r: &PacketTriRays,
        rays: u32,
        best: &mut PacketBest,
        closest: bool,
    ) -> (u32, u64) {
        /// Lanes of one vector.
        const HALF: usize = 8;
        // SAFETY: the caller's guarantee: the processor has the features of every intrinsic.
        unsafe {
            let [kx, ky, kz] = r.axes;
            let zero = _mm256_setzero_ps();
            let abs = |x: __m256| _mm256_andnot_ps(_mm256_set1_ps(-0.0), x);
            let bits = |m: __m256| _mm256_movemask_ps(m) as u32;
            let lt = |a: __m256, b: __m256| _mm256_cmp_ps::<_CMP_LT_OQ>(a, b);
            let gt = |a: __m256, b: __m256| _mm256_cmp_ps::<_CMP_GT_OQ>(a, b);
            let normal = |x: __m256| {
                _mm256_and_ps(
                    _mm256_cmp_ps::<_CMP_GE_OQ>(abs(x), _mm256_set1_ps(f32::MIN_POSITIVE)),
                    lt(abs(x), _mm256_set1_ps(f32::INFINITY)),
                )
            };
            // The lanes of `lanes` (eight bits) as a comparison's lanes.
            let lanes_of = |lanes: u32| {
                let bit = _mm256_setr_epi32(1, 2, 4, 8, 16, 32, 64, 128);
                let set = _mm256_and_si256(_mm256_set1_epi32(lanes as i32), bit);
                _mm256_castsi256_ps(_mm256_cmpeq_epi32(set, bit))
            };
            let (mut hit_rays, mut special_pairs) = (0u32, 0u64);
            for h in 0..2 {
                let rays_h = (rays >> (HALF * h)) & 0xff;
                if rays_h == 0 {
                    continue;
                }
                // Aligned loads and stores: each half of a `Lanes` is 32 bytes at an offset of 0
                // or 32 from a 64-aligned start.
                let load = |l: &super::Lanes| _mm256_load_ps(l.0.as_ptr().add(HALF * h));
                let o_k = [load(&r.origin_k[0]), load(&r.origin_k[1]), load(&r.origin_k[2])];
                let (sx, sy, sz) = (load(&r.shear[0]), load(&r.shear[1]), load(&r.shear[2]));
                for lane in 0..LANES {
                    let id = block.ids[lane];
                    if id == UNUSED {
                        continue;
                    }
                    let at = |k: usize, axis: usize| block.v[3 * k + axis][lane];
                    // As in `block_avx512`.
                    macro_rules! project {
                        ($k:expr) => {{
                            let x = _mm256_sub_ps(_mm256_set1_ps(at($k, kx)), o_k[0]);
                            let y = _mm256_sub_ps(_mm256_set1_ps(at($k, ky)), o_k[1]);
                            let z = _mm256_sub_ps(_mm256_set1_ps(at($k, kz)), o_k[2]);
                            (_mm256_sub_ps(x, _mm256_mul_ps(sx, z)), _mm256_sub_ps(y, _mm256_mul_ps(sy, z)), z)
                        }};
                    }
                    let (ax, ay, a_z) = project!(0);
                    let (bx, by, b_z) = project!(1);
                    let (cx, cy, c_z) = project!(2);
                    let e0 = _mm256_sub_ps(_mm256_mul_ps(cx, by), _mm256_mul_ps(cy, bx));
                    let e1 = _mm256_sub_ps(_mm256_mul_ps(ax, cy), _mm256_mul_ps(ay, cx));
                    let e2 = _mm256_sub_ps(_mm256_mul_ps(bx, ay), _mm256_mul_ps(by, ax));
                    let negative = bits(_mm256_or_ps(_mm256_or_ps(lt(e0, zero), lt(e1, zero)), lt(e2, zero)));
                    let positive = bits(_mm256_or_ps(_mm256_or_ps(gt(e0, zero), gt(e1, zero)), gt(e2, zero)));
                    let inside = !(negative & positive) & rays_h;
                    if inside == 0 {
                        continue;
                    }
                    let all_normal = bits(_mm256_and_ps(_mm256_and_ps(normal(e0), normal(e1)), normal(e2)));
                    let mut special = inside & !all_normal;
                    let candidate = inside & all_normal;
                    if candidate != 0 {
                        let (az, bz, cz) = (_mm256_mul_ps(sz, a_z), _mm256_mul_ps(sz, b_z), _mm256_mul_ps(sz, c_z));
                        let det = _mm256_add_ps(_mm256_add_ps(e0, e1), e2);
                        let t_scaled = _mm256_add_ps(
                            _mm256_add_ps(_mm256_mul_ps(e0, az), _mm256_mul_ps(e1, bz)),
                            _mm256_mul_ps(e2, cz),
                        );
                        let inv_det = _mm256_div_ps(_mm256_set1_ps(1.0), det);
                        let t = _mm256_mul_ps(t_scaled, inv_det);
                        let finite = bits(lt(abs(t), _mm256_set1_ps(f32::INFINITY)));
                        special |= candidate & !finite;
                        let candidate = candidate & finite;
                        // The box-stretch correction, as the block test computes it.
                        let (mut enter, mut exit) = (_mm256_set1_ps(f32::NEG_INFINITY), _mm256_set1_ps(f32::INFINITY));
                        for axis in 0..3 {
                            let (p, q, s) = (at(0, axis), at(1, axis), at(2, axis));
                            let (lo, hi) = (_mm256_set1_ps(p.min(q).min(s)), _mm256_set1_ps(p.max(q).max(s)));
                            let inv = load(&packet.inv_dir[axis]);
                            let o = load(&packet.origin[axis]);
                            let positive_dir = _mm256_cmp_ps::<_CMP_GE_OQ>(inv, zero);
                            let near = _mm256_blendv_ps(hi, lo, positive_dir);
                            let far = _mm256_blendv_ps(lo, hi, positive_dir);
                            let t_near = _mm256_mul_ps(_mm256_sub_ps(near, o), inv);
                            let t_far = _mm256_mul_ps(
                                _mm256_mul_ps(_mm256_sub_ps(far, o), inv),
                                _mm256_set1_ps(ROBUST_FAR_SCALE),
                            );
                            // `max(a, b)` is `a > b ? a : b`: the block test's `keep_greater`.
                            enter = _mm256_max_ps(t_near, enter);
                            exit = _mm256_min_ps(t_far, exit);
                        }
                        let in_box = bits(_mm256_cmp_ps::<_CMP_LE_OQ>(enter, exit));
                        let t = _mm256_blendv_ps(t, enter, lt(t, enter));
                        let t = _mm256_blendv_ps(t, exit, gt(t, exit));
                        let best_t = load(&best.t);
                        let in_range = bits(_mm256_and_ps(
                            _mm256_cmp_ps::<_CMP_GE_OQ>(t, load(&packet.t_min)),
                            _mm256_cmp_ps::<_CMP_LE_OQ>(t, best_t),
                        ));
                        let hit = candidate & in_box & in_range;
                        hit_rays |= hit << (HALF * h);
                        if closest && hit != 0 {
                            let prim = _mm256_set1_epi32(id as i32);
                            let best_prim = _mm256_castps_si256(load(&best.prim));
                            // `prim < best_prim` as unsigned numbers: both flipped at the top
                            // bit, then compared as signed ones.
                            let top = _mm256_set1_epi32(i32::MIN);
                            let lower = _mm256_castsi256_ps(_mm256_cmpgt_epi32(
                                _mm256_xor_si256(best_prim, top),
                                _mm256_xor_si256(prim, top),
                            ));
                            let better = _mm256_and_ps(
                                lanes_of(hit),
                                _mm256_or_ps(
                                    lt(t, best_t),
                                    _mm256_and_ps(_mm256_cmp_ps::<_CMP_EQ_OQ>(t, best_t), lower),
                                ),
                            );
                            let store = |l: &mut super::Lanes, x: __m256| {
                                let at = l.0.as_mut_ptr().add(HALF * h);
                                _mm256_store_ps(at, _mm256_blendv_ps(_mm256_load_ps(at), x, better))
                            };
                            store(&mut best.t, t);
                            store(&mut best.u, _mm256_mul_ps(e1, inv_det));
                            store(&mut best.v, _mm256_mul_ps(e2, inv_det));
                            store(&mut best.prim, _mm256_castsi256_ps(prim));
                        }
                    }
                    special_pairs |= (special as u64) << (16 * lane + HALF * h);
                }
            }
            (hit_rays, special_pairs)
        }
    }
}
