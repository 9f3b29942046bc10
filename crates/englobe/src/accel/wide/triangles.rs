//! Triangles stored for SIMD intersection: blocks of four, vertices as a structure of arrays, and
//! the watertight test of Woop, Benthin and Wald (2013), "Watertight Ray/Triangle Intersection"
//! (JCGT 2(1)) run on the four at once.
//!
//! The block layout is Embree's `Triangle4` (Wald et al. 2014, "Embree: A Kernel Framework for
//! Efficient CPU Ray Tracing"), with the three vertices kept as they are rather than as edges, because the
//! watertight test shears the vertices themselves. A ray's axes `kx, ky, kz` only choose which
//! rows of the block are read, so no data moves per ray.
//!
//! The lanes compute exactly what the scalar test [`intersect_triangle`] computes, with the same
//! operations in the same order (no fused multiply-add; only the box-stretch correction takes its
//! three axes in another order, which cannot change its result, see [`intersect_block`]), so a
//! lane hits if and only if the scalar test hits, at the same `t`. The scalar test's rare paths
//! are not duplicated: a lane whose edge functions are not all normal numbers (zero, subnormal,
//! infinite: a ray through an edge or a vertex, or a scene at an extreme scale), whose
//! determinant (their sum) overflows or whose `t` is not finite is reported as *special*, and the
//! caller runs the scalar test on that triangle. Lanes whose edge functions have strictly
//! opposite signs are misses whatever the precision (rounding is monotonic, so a nonzero `f32`
//! edge function has the sign of the exact one), which the scalar test's `f64` path would also
//! conclude. Zero-area triangles are never stored: the scalar test never hits them.

use glam::{BVec4A, Vec3, Vec4};

use crate::PrimHit;
use crate::Ray;
use crate::geom::aabb::ROBUST_FAR_SCALE;
use crate::shapes::{WatertightRay, intersect_triangle, is_degenerate};

/// Triangles per block.
pub const LANES: usize = 4;

/// The triangle index of a block's unused lanes (they repeat a used lane's vertices).
pub const UNUSED: u32 = u32::MAX;

/// Four triangles: row `3 * vertex + axis` holds that coordinate of that vertex for each lane.
#[derive(Clone, Copy, Debug, PartialEq)]
#[repr(C, align(16))]
pub struct TriBlock {
    /// The vertices' coordinates, one row per coordinate, one column per lane.
    pub v: [[f32; LANES]; 9],
    /// Each lane's triangle index in the mesh, or [`UNUSED`].
    pub ids: [u32; LANES],
}

const _: () = assert!(std::mem::size_of::<TriBlock>() == 160);

impl TriBlock {
    /// A block over up to four triangles (at least one); unused lanes repeat the first.
    pub fn new(triangles: &[(u32, [Vec3; 3])]) -> Self {
        assert!((1..=LANES).contains(&triangles.len()), "a block holds 1 to {LANES} triangles");
        let mut block = TriBlock { v: [[0.0; LANES]; 9], ids: [UNUSED; LANES] };
        for lane in 0..LANES {
            let (id, verts) = triangles.get(lane).copied().unwrap_or((UNUSED, triangles[0].1));
            block.ids[lane] = id;
            for (k, p) in verts.iter().enumerate() {
                for axis in 0..3 {
                    block.v[3 * k + axis][lane] = p[axis];
                }
            }
        }
        block
    }

    /// The vertices of lane `lane`.
    #[inline(always)]
    pub fn vertices(&self, lane: usize) -> [Vec3; 3] {
        let v = &self.v;
        [0, 1, 2].map(|k| Vec3::new(v[3 * k][lane], v[3 * k + 1][lane], v[3 * k + 2][lane]))
    }

    /// Number of used lanes.
    #[inline(always)]
    pub fn used(&self) -> u32 {
        self.used_lanes().count_ones()
    }

    /// The used lanes, bit per lane (an unused lane repeats the first's triangle: a test of the
    /// block leaves it out).
    #[inline(always)]
    pub fn used_lanes(&self) -> u32 {
        (0..LANES).filter(|&lane| self.ids[lane] != UNUSED).fold(0, |m, lane| m | 1 << lane)
    }
}

/// Whether the triangle can ever be hit (it has an area): the rule of the scalar test.
pub fn is_storable(v: &[Vec3; 3]) -> bool {
    !is_degenerate(v[0], v[1], v[2])
}

/// A ray prepared for block tests: the watertight test's constants, and what the box-stretch
/// correction of a hit needs, all in the ray's axis order `kx, ky, kz`, so that a block test
/// indexes nothing but the block's rows. The ray itself is not copied in: the rare special lanes
/// get it from the caller (see [`TriRay::scalar`]).
#[derive(Clone, Copy, Debug)]
pub struct TriRay {
    /// The origin's coordinates along `kx, ky, kz`.
    origin: [Vec4; 3],
    /// The inverse direction's components along `kx` and `ky` (along `kz` the box correction
    /// uses the shear's, the same number: see [`intersect_block`]).
    inv_dir: [Vec4; 2],
    /// The axes `kx, ky, kz`: each below 3 (an invariant of [`TriRay::new`], which
    /// [`TriRay::row`] relies on to read a block without a bounds check).
    axes: [usize; 3],
    shear: [Vec4; 3],
    /// The lanes of axis `kx`, `ky` where the ray goes down it (`inv_dir < 0`, all of them or
    /// none): where the box correction's near and far planes are a triangle's largest and
    /// smallest coordinates.
    down: [BVec4A; 2],
    t_min: Vec4,
}

impl TriRay {
    /// Prepares `ray`.
    #[inline(always)]
    pub fn new(ray: &Ray) -> Self {
        let watertight = WatertightRay::new(ray);
        // Four-entry arrays, not vectors: `Vec3`'s index is a chain of comparisons per lookup, and
        // an axis (two bits) indexes four entries without a bounds check.
        let (o, inv, s) =
            (ray.origin_a().extend(0.0).to_array(), ray.inv_dir_a().extend(0.0).to_array(), watertight.shear());
        let axes = watertight.axes();
        let inv_dir = [0, 1].map(|k| Vec4::splat(inv[axes[k]]));
        TriRay {
            origin: axes.map(|a| Vec4::splat(o[a])),
            inv_dir,
            axes,
            shear: [0, 1, 2].map(|a| Vec4::splat(s[a])),
            down: inv_dir.map(|inv| inv.cmplt(Vec4::ZERO)),
            t_min: Vec4::splat(ray.t_min),
        }
    }

    /// [`TriRay::new`] with AVX's variable shuffle: the ray's vectors are put in the order
    /// `kx, ky, kz` lane by lane and the lanes broadcast from registers, with one division for
    /// the three of the shear, where the portable form stores the vectors, reads each entry back
    /// through its axis and divides three times (a third fewer instructions in the AVX2 walk).
    /// The same numbers: each lane is divided as the scalar test divides, and IEEE division
    /// rounds each exactly.
    ///
    /// # Safety
    /// The processor has AVX.
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx")]
    #[inline]
    pub unsafe fn new_avx(ray: &Ray) -> Self {
        use std::arch::x86_64::*;
        let d: __m128 = ray.dir_a().into();
        let entry = &ORDERS[axes_code(d) & 7];
        let axes = [entry[0] as usize, entry[1] as usize, entry[2] as usize];
        // SAFETY: an entry is sixteen bytes.
        let order = unsafe { _mm_loadu_si128(entry.as_ptr().cast()) };
        let (o, inv, d) = (
            _mm_permutevar_ps(ray.origin_a().into(), order),
            _mm_permutevar_ps(ray.inv_dir_a().into(), order),
            _mm_permutevar_ps(d, order),
        );
        // `(d[kx], d[ky], 1) / d[kz]`: `WatertightRay::new`'s three quotients.
        let shear = _mm_div_ps(_mm_blend_ps::<0b0100>(d, _mm_set1_ps(1.0)), _mm_permute_ps::<0b10_10_10_10>(d));
        let [inv_x, inv_y, _] = lanes(inv);
        let inv_dir = [inv_x, inv_y];
        TriRay {
            origin: lanes(o),
            inv_dir,
            axes,
            shear: lanes(shear),
            down: inv_dir.map(|inv| inv.cmplt(Vec4::ZERO)),
            t_min: Vec4::splat(ray.t_min),
        }
    }

    /// Row `axis` (0, 1, 2 for `kx, ky, kz`) of vertex `k` of `block`: that coordinate of the
    /// vertex for each lane.
    #[inline(always)]
    fn row(&self, block: &TriBlock, k: usize, axis: usize) -> Vec4 {
        let index = 3 * k + self.axes[axis];
        debug_assert!(k < 3 && self.axes[axis] < 3);
        // SAFETY: `k < 3` at every call (a literal), and the axes are below 3 (see `axes`), so
        // the index is below the block's nine rows.
        Vec4::from_array(*unsafe { block.v.get_unchecked(index) })
    }

    /// The scalar test of lane `lane` with the interval `ray.t_min..=t_max`, `ray` being the ray
    /// this was prepared from: for special lanes.
    #[inline(never)]
    #[cold]
    pub fn scalar(ray: &Ray, block: &TriBlock, lane: usize, t_max: f32) -> Option<PrimHit> {
        let [a, b, c] = block.vertices(lane);
        intersect_triangle(&ray.with_range(ray.t_min, t_max), &WatertightRay::new(ray), a, b, c)
    }
}

/// [`WatertightRay::AXES`] unpacked: each order `[kx, ky, kz, 3]` (the last lane left in place)
/// as the control of a shuffle, the order of code `c` at entry `c`; the last two entries unused.
#[cfg(target_arch = "x86_64")]
const ORDERS: [[u32; 4]; 8] = {
    let mut orders = [[0, 1, 2, 3]; 8];
    let mut code = 0;
    while code < 6 {
        let bits = WatertightRay::AXES >> (6 * code);
        orders[code] = [(bits & 3) as u32, (bits >> 2 & 3) as u32, (bits >> 4 & 3) as u32, 3];
        code += 1;
    }
    orders
};

/// [`WatertightRay::axes_code`] of the direction `d` (its lanes 0 to 2) with vector operations:
/// `kz` is the first axis whose component's magnitude is the largest, as there.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx")]
#[inline]
fn axes_code(d: std::arch::x86_64::__m128) -> usize {
    use std::arch::x86_64::*;
    let a = _mm_andnot_ps(_mm_set1_ps(-0.0), d);
    // Lanes 0 to 2 each the largest of the three (the shuffles read no lane 3 into them, and the
    // mask below leaves lane 3 out).
    let largest = _mm_max_ps(a, _mm_max_ps(_mm_permute_ps::<0b11_00_10_01>(a), _mm_permute_ps::<0b11_01_00_10>(a)));
    let kz = (_mm_movemask_ps(_mm_cmpeq_ps(a, largest)) & 0b111).trailing_zeros();
    let down = _mm_movemask_ps(_mm_cmplt_ps(d, _mm_setzero_ps())) as u32 >> kz & 1;
    (2 * kz + down) as usize
}

/// Lanes 0, 1 and 2 of `v`, each broadcast to a vector.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx")]
#[inline]
fn lanes(v: std::arch::x86_64::__m128) -> [Vec4; 3] {
    use std::arch::x86_64::_mm_permute_ps;
    [
        _mm_permute_ps::<0>(v).into(),
        _mm_permute_ps::<0b01_01_01_01>(v).into(),
        _mm_permute_ps::<0b10_10_10_10>(v).into(),
    ]
}

/// What the four lanes of a block gave. The distances and barycentrics stay vectors: a caller
/// reads them lane by lane only for the lanes hit, so a block that nothing hits (most of them)
/// writes nothing to memory (arrays indexed by a lane number would be stored on every return).
#[derive(Clone, Copy, Debug)]
pub struct BlockHits {
    /// Lanes hit within the interval (bit per lane).
    pub hit: u32,
    /// Lanes the scalar test must decide.
    pub special: u32,
    /// Hit distance of each hit lane.
    t: Vec4,
    /// First barycentric of each hit lane.
    u: Vec4,
    /// Second barycentric of each hit lane.
    v: Vec4,
}

impl BlockHits {
    /// No lane hit and none special.
    pub const NONE: BlockHits = BlockHits { hit: 0, special: 0, t: Vec4::ZERO, u: Vec4::ZERO, v: Vec4::ZERO };

    /// The hit of lane `lane`, one of the lanes [`BlockHits::hit`] holds.
    #[inline(always)]
    pub fn lane(&self, lane: usize) -> PrimHit {
        debug_assert!(self.hit >> lane & 1 != 0);
        let (t, u, v) = (self.t.to_array(), self.u.to_array(), self.v.to_array());
        PrimHit { t: t[lane], u: u[lane], v: v[lane] }
    }
}

/// `if a > b { a } else { b }` per lane, as the scalar slab test: `b` when `a` is NaN, and when
/// both are zeros. On x86-64 this is exactly what `maxps` computes (Intel's definition: the
/// second operand unless the first is greater), one instruction instead of a compare and a blend.
/// Not glam's `Vec4::max`, whose NaN behaviour is left to each architecture.
#[inline(always)]
fn keep_greater(a: Vec4, b: Vec4) -> Vec4 {
    // SAFETY: SSE is part of every x86-64 processor.
    #[cfg(target_arch = "x86_64")]
    return unsafe { std::arch::x86_64::_mm_max_ps(a.into(), b.into()) }.into();
    #[cfg(not(target_arch = "x86_64"))]
    Vec4::select(a.cmpgt(b), a, b)
}

/// `if a < b { a } else { b }` per lane: `minps` on x86-64, as [`keep_greater`] is `maxps`.
#[inline(always)]
fn keep_less(a: Vec4, b: Vec4) -> Vec4 {
    // SAFETY: as in `keep_greater`.
    #[cfg(target_arch = "x86_64")]
    return unsafe { std::arch::x86_64::_mm_min_ps(a.into(), b.into()) }.into();
    #[cfg(not(target_arch = "x86_64"))]
    Vec4::select(a.cmplt(b), a, b)
}

/// `(lo, hi)`, the two swapped in the lanes of `swap`: `select(swap, hi, lo)` and
/// `select(swap, lo, hi)` in four bit operations on x86-64 rather than six.
#[inline(always)]
fn order(lo: Vec4, hi: Vec4, swap: BVec4A) -> (Vec4, Vec4) {
    // SAFETY: SSE is part of every x86-64 processor.
    #[cfg(target_arch = "x86_64")]
    return unsafe {
        use std::arch::x86_64::{_mm_and_ps, _mm_xor_ps};
        let differ = _mm_and_ps(_mm_xor_ps(lo.into(), hi.into()), swap.into());
        (_mm_xor_ps(lo.into(), differ).into(), _mm_xor_ps(hi.into(), differ).into())
    };
    #[cfg(not(target_arch = "x86_64"))]
    (Vec4::select(swap, hi, lo), Vec4::select(swap, lo, hi))
}

/// The watertight test of the ray against the four triangles of `block`, within
/// `t_min..=t_max`. Every lane reports what [`intersect_triangle`] would, or is special; `None`
/// when the edge functions alone exclude every lane (most blocks), so that a caller's loop goes
/// straight on to the next block.
#[inline(always)]
pub fn intersect_block(block: &TriBlock, r: &TriRay, t_max: f32) -> Option<BlockHits> {
    let [sx, sy, sz] = r.shear;
    // Vertex k relative to the origin, sheared: exactly the scalar test's `ax`, `ay`, `az`.
    let project = |k: usize| {
        let (x, y, z) =
            (r.row(block, k, 0) - r.origin[0], r.row(block, k, 1) - r.origin[1], r.row(block, k, 2) - r.origin[2]);
        (x - sx * z, y - sy * z, z)
    };
    let (ax, ay, a_z) = project(0);
    let (bx, by, b_z) = project(1);
    let (cx, cy, c_z) = project(2);
    let e0 = cx * by - cy * bx;
    let e1 = ax * cy - ay * cx;
    let e2 = bx * ay - by * ax;
    let zero = Vec4::ZERO;
    let negative = e0.cmplt(zero) | e1.cmplt(zero) | e2.cmplt(zero);
    let positive = e0.cmpgt(zero) | e1.cmpgt(zero) | e2.cmpgt(zero);
    let inside = !(negative & positive);
    if !inside.any() {
        return None;
    }
    // The lanes whose edge functions are all normal numbers (as the scalar test asks) and whose
    // determinant is finite. Inside its edges, a lane's edge functions have one sign, so the
    // determinant is at least as large as each: an infinite or NaN one makes it infinite or NaN,
    // and the smallest is the one to compare with the smallest normal number (a NaN that `min`
    // passed over has made the determinant NaN already). A finite sum of normal numbers that
    // overflows is left to the scalar test too.
    let det = e0 + e1 + e2;
    let smallest = e0.abs().min(e1.abs()).min(e2.abs());
    let regular = smallest.cmpge(Vec4::splat(f32::MIN_POSITIVE)) & det.abs().cmplt(Vec4::INFINITY);
    let special = inside & !regular;
    let candidate = inside & regular;
    if !candidate.any() {
        return Some(BlockHits { special: special.bitmask(), ..BlockHits::NONE });
    }
    let (az, bz, cz) = (sz * a_z, sz * b_z, sz * c_z);
    let t_scaled = e0 * az + e1 * bz + e2 * cz;
    let inv_det = Vec4::ONE / det;
    let t = t_scaled * inv_det;
    let finite = t.abs().cmplt(Vec4::INFINITY);
    let special = special | (candidate & !finite);
    let candidate = candidate & finite;

    // The box-stretch correction of the scalar test's `finish`: the stretch of the whole line
    // inside the triangle's box, computed as the robust slab test computes it. Along the ray's
    // main axis `kz` the vertices' slab distances are `az`, `bz` and `cz` themselves: a plane's
    // distance there is `(v - o) * inv_dir[kz]`, the same product (`shear.z` is `1 / d[kz]`, the
    // inverse direction's lane bit for bit, `d[kz]` never being zero), and rounding is monotonic,
    // so the nearest and farthest of the three are the distances of the box's near and far planes.
    // They are finite in every candidate lane (an infinite or NaN one would have made `t` so).
    let near_z = az.min(bz).min(cz);
    let far_z = az.max(bz).max(cz) * ROBUST_FAR_SCALE;
    // The other two axes, `kx` and `ky`. The axes are taken in the order `kz, kx, ky` rather than
    // `x, y, z`: the largest entry and the smallest exit do not depend on the order (a NaN
    // distance is skipped wherever it comes; only the sign of a zero could differ, and it compares
    // equal), and the rows are the ones the projection read.
    let (mut enter, mut exit) = (near_z, far_z);
    for axis in 0..2 {
        let (p, q, s) = (r.row(block, 0, axis), r.row(block, 1, axis), r.row(block, 2, axis));
        let (lo, hi) = (p.min(q).min(s), p.max(q).max(s));
        let inv = r.inv_dir[axis];
        let (near, far) = order(lo, hi, r.down[axis]);
        let t_near = (near - r.origin[axis]) * inv;
        let t_far = (far - r.origin[axis]) * inv * ROBUST_FAR_SCALE;
        enter = keep_greater(t_near, enter);
        exit = keep_less(t_far, exit);
    }
    let in_box = enter.cmple(exit);
    // `if t < enter { enter } else { t }`, then `if t > exit { exit } else { t }`.
    let t = keep_greater(enter, t);
    let t = keep_less(exit, t);
    let in_range = t.cmpge(r.t_min) & t.cmple(Vec4::splat(t_max));
    let hit = candidate & in_box & in_range;
    Some(BlockHits { hit: hit.bitmask(), special: special.bitmask(), t, u: e1 * inv_det, v: e2 * inv_det })
}

#[cfg(test)]
mod tests {
    use rand::{RngExt, SeedableRng};
    use rand_pcg::Pcg32;

    use super::*;

    /// Uniform numbers in `[0, 1)` from a seeded PCG32, so that failures reproduce.
    fn rng(seed: u64) -> impl FnMut() -> f32 {
        let mut rng = Pcg32::seed_from_u64(seed);
        move || rng.random()
    }

    /// A point of the cube `[-1, 1)^3`.
    fn point(next: &mut impl FnMut() -> f32) -> Vec3 {
        Vec3::new(next(), next(), next()) * 2.0 - 1.0
    }

    /// `n` random triangles in that cube, numbered from 0.
    fn soup(next: &mut impl FnMut() -> f32, n: usize) -> Vec<(u32, [Vec3; 3])> {
        (0..n).map(|k| (k as u32, [point(next), point(next), point(next)])).collect()
    }

    /// The lanes against the scalar test, lane by lane, special lanes resolved by it.
    fn agree(tris: &[(u32, [Vec3; 3])], ray: &Ray) -> u32 {
        let block = TriBlock::new(tris);
        let r = TriRay::new(ray);
        let w = WatertightRay::new(ray);
        let got = intersect_block(&block, &r, ray.t_max).unwrap_or(BlockHits::NONE);
        let mut hits = 0;
        for (lane, (_, [a, b, c])) in tris.iter().enumerate() {
            let expected = intersect_triangle(ray, &w, *a, *b, *c);
            let lane_hit = if got.special >> lane & 1 != 0 {
                TriRay::scalar(ray, &block, lane, ray.t_max)
            } else if got.hit >> lane & 1 != 0 {
                Some(got.lane(lane))
            } else {
                None
            };
            assert_eq!(lane_hit, expected, "lane {lane} of {tris:?}, {ray:?}");
            hits += lane_hit.is_some() as u32;
        }
        hits
    }

    #[test]
    fn lanes_agree_with_the_scalar_test_on_random_triangles() {
        let mut next = rng(0x9e37_79b9);
        let mut hits = 0;
        for i in 0..20_000 {
            let tris = soup(&mut next, 1 + i % 4);
            let origin = point(&mut next) * 3.0;
            let target = point(&mut next) * 0.5;
            let t_max = [f32::INFINITY, 2.0, 0.5][i % 3];
            hits += agree(&tris, &Ray::segment(origin, target - origin, 0.0, t_max));
        }
        assert!(hits > 1000, "{hits}");
    }

    #[test]
    fn lanes_agree_at_the_ends_of_the_interval() {
        // Rays that start on a triangle, and rays whose interval begins or ends exactly where the
        // scalar test hits (or one float past it), through vertices (the hit then lies on the
        // triangle's box, where the box correction's widened far end decides) and inside points:
        // anything a block test drops or keeps early must agree with the scalar test there.
        let mut next = rng(0x51ab_2009);
        let mut hits = 0;
        for i in 0..20_000 {
            let tris = soup(&mut next, 1 + i % 4);
            let dir = point(&mut next);
            let [a, b, c] = tris[0].1;
            let (u, v) = (next() * 0.5, next() * 0.5);
            let on = if i % 2 == 0 { [a, b, c][i / 2 % 3] } else { a + (b - a) * u + (c - a) * v };
            hits += agree(&tris, &Ray::new(on, dir));
            hits += agree(&tris, &Ray::new(on, -dir));
            let origin = on - dir * 2.0;
            let ray = Ray::new(origin, dir);
            if let Some(h) = intersect_triangle(&ray, &WatertightRay::new(&ray), a, b, c) {
                for (t_min, t_max) in
                    [(0.0, h.t), (0.0, h.t.next_down()), (h.t, f32::INFINITY), (h.t.next_up(), f32::INFINITY)]
                {
                    hits += agree(&tris, &Ray::segment(origin, dir, t_min, t_max));
                }
            }
        }
        assert!(hits > 10_000, "{hits}");
    }

    #[test]
    fn lanes_agree_on_edges_vertices_and_axis_parallel_rays() {
        // A fan of triangles on an integer grid, with rays through its vertices and edges along
        // the axes and diagonals: edge functions of exactly zero, the scalar test's f64 path.
        let grid = |x: f32, y: f32| Vec3::new(x, y, 0.0);
        let tris = [
            (0, [grid(0.0, 0.0), grid(1.0, 0.0), grid(1.0, 1.0)]),
            (1, [grid(0.0, 0.0), grid(1.0, 1.0), grid(0.0, 1.0)]),
            (2, [grid(1.0, 0.0), grid(2.0, 0.0), grid(1.0, 1.0)]),
            (3, [grid(0.0, 1.0), grid(1.0, 1.0), grid(0.0, 2.0)]),
        ];
        let mut hits = 0;
        for i in 0..=8 {
            for j in 0..=8 {
                let o = Vec3::new(i as f32 * 0.25, j as f32 * 0.25, 2.0);
                for d in [-Vec3::Z, Vec3::new(0.0, -0.0, -1.0), Vec3::new(0.25, 0.25, -1.0), Vec3::new(-0.5, 0.0, -1.0)]
                {
                    hits += agree(&tris, &Ray::new(o, d));
                }
            }
        }
        assert!(hits > 100, "{hits}");
        // Rays in the triangles' plane, and scenes scaled to the limits of f32.
        for s in [1e-30f32, 1e-20, 1.0, 1e20, 1e30] {
            let scaled: Vec<(u32, [Vec3; 3])> = tris.iter().map(|(i, v)| (*i, v.map(|p| p * s))).collect();
            agree(&scaled, &Ray::new(Vec3::new(0.25, 0.5, -1.0) * s, Vec3::Z));
            agree(&scaled, &Ray::new(Vec3::new(-1.0, 0.25, 0.0) * s, Vec3::X));
        }
    }

    /// Every number of a prepared ray, as bits.
    #[cfg(target_arch = "x86_64")]
    fn bits(r: &TriRay) -> Vec<u32> {
        let vectors = r.origin.iter().chain(&r.inv_dir).chain(&r.shear).chain([&r.t_min]);
        let mut bits: Vec<u32> = vectors.flat_map(|v| v.to_array().map(f32::to_bits)).collect();
        bits.extend(r.axes.map(|a| a as u32));
        bits.extend(r.down.map(|d| d.bitmask()));
        bits
    }

    #[cfg(target_arch = "x86_64")]
    #[test]
    fn the_avx_preparation_is_the_portable_one_bit_for_bit() {
        if !std::arch::is_x86_feature_detected!("avx") {
            return;
        }
        let mut next = rng(0x0a5e_7a1e);
        let mut dirs: Vec<Vec3> = (0..20_000).map(|_| point(&mut next)).collect();
        // Components of equal magnitude (which axis is `kz`), zeros of either sign, tiny and huge
        // components: where the axes' choice and the divisions could part.
        let values = [-2.0, -1.0, -0.0, 0.0, 1e-30, 1.0, 2.0, 3e30];
        for x in values {
            for y in values {
                for z in values {
                    dirs.push(Vec3::new(x, y, z));
                }
            }
        }
        let mut compared = 0;
        for d in dirs {
            let ray = Ray::segment(point(&mut next), d, next(), f32::INFINITY);
            if !ray.is_valid() {
                continue;
            }
            // SAFETY: the processor has AVX (checked above).
            let avx = unsafe { TriRay::new_avx(&ray) };
            assert_eq!(bits(&avx), bits(&TriRay::new(&ray)), "{ray:?}");
            compared += 1;
        }
        assert!(compared > 20_000, "{compared}");
    }

    #[test]
    fn the_shear_along_the_main_axis_is_the_inverse_direction() {
        // What lets the box correction take its distances along `kz` from the projection: the
        // shear's `1 / d[kz]` and the ray's inverse direction there are one number, for ordinary
        // directions and for components at the ends of the range.
        let mut next = rng(0x1d1f_2e3a);
        let values = [-3e38, -1.0, -1e-30, -1e-38, 0.0, 1e-45, 1e-38, 0.5, 7.0, 3e38];
        let mut dirs: Vec<Vec3> = (0..10_000).map(|_| point(&mut next)).collect();
        for x in values {
            for y in values {
                for z in values {
                    dirs.push(Vec3::new(x, y, z));
                }
            }
        }
        let mut compared = 0;
        for d in dirs {
            let ray = Ray::new(Vec3::ZERO, d);
            if !ray.is_valid() {
                continue;
            }
            let w = WatertightRay::new(&ray);
            let kz = w.axes()[2];
            assert_eq!(w.shear().z.to_bits(), ray.inv_dir()[kz].to_bits(), "{d:?}");
            compared += 1;
        }
        assert!(compared > 10_000, "{compared}");
    }

    #[test]
    fn unused_lanes_repeat_the_first_triangle() {
        let t = (7, [Vec3::ZERO, Vec3::X, Vec3::Y]);
        let block = TriBlock::new(&[t]);
        assert_eq!(block.ids, [7, UNUSED, UNUSED, UNUSED]);
        assert_eq!(block.used(), 1);
        assert_eq!(block.vertices(3), t.1);
        let hits = intersect_block(&block, &TriRay::new(&Ray::new(Vec3::new(0.2, 0.2, 1.0), -Vec3::Z)), 10.0).unwrap();
        assert_eq!(hits.hit, 0b1111);
        assert!(!is_storable(&[Vec3::ZERO, Vec3::X, Vec3::X * 2.0]) && is_storable(&t.1));
    }
}
