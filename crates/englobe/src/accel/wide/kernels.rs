//! The slab test of a wide node's eight children at once, one implementation per instruction set
//! (see [`super::isa`]). Each computes, per child, exactly what the scalar robust slab test
//! computes ([`super::node::child_entry_scalar`], Williams, Barrus, Morley and Shirley (2005) with
//! the far distance scaled as in Ize (2013), "Robust BVH Ray Traversal", the scale folded into the
//! ray's inverse direction): the same subtractions (the plane from the origin) and products (by
//! the negated inverse) in the same order, and the same handling of NaN (an origin on the plane of
//! a parallel ray leaves the interval unchanged). The x86 `max`/`min` instructions return their
//! second operand when either is NaN, which is the scalar test's
//! `if t_near > enter { t_near } else { enter }`; the portable kernel spells that comparison out,
//! because NEON's `max` propagates NaN instead.
//!
//! For the rays to which it applies, the AVX-512 walk tests nodes in a fused form instead
//! ([`Avx512Fused`], see [`super::fused`]), matched bit for bit by its own scalar reference.
//!
//! The kernels are `unsafe` only because the x86 ones need their instruction set: a kernel may be
//! called only from code compiled with its target features, on a processor that has them, which
//! the dispatch in [`super::traverse`] guarantees.

use glam::Vec4;

use super::node::{NodeRay, WIDTH, WideNode};

/// A slab test of all children of a node.
pub trait NodeKernel: Copy {
    /// Whether the processor that runs this kernel has AVX (the x86 kernels say so): code
    /// compiled with the kernel's target features may then use it, as the triangle test's set-up
    /// does ([`super::triangles::TriRay::new_avx`]). False unless a kernel says so.
    const AVX: bool = false;

    /// The kernel made ready for one query's ray: a kernel with per-ray constants makes them
    /// here, at the start of the walk, in the function compiled for its instruction set, so
    /// that they reach the walk in registers. The kernel itself by default.
    ///
    /// # Safety
    /// As [`NodeKernel::children`].
    #[inline(always)]
    unsafe fn for_ray(self, ray: &NodeRay) -> Self {
        let _ = ray;
        self
    }

    /// Tests the ray against the eight children's boxes within `t_min..=limit`: bit `i` of the
    /// result is set if child `i` is entered, and `dist[i]` is then its entry distance.
    ///
    /// # Safety
    /// The caller is compiled with the kernel's target features and runs on a processor that
    /// has them.
    unsafe fn children(self, node: &WideNode, ray: &NodeRay, limit: f32, dist: &mut [f32; WIDTH]) -> u32;

    /// The same test, with `dist[i]` the distance at which the ray leaves child `i` (its exit,
    /// within `limit`) instead of the one at which it enters: what occlusion walks order the
    /// children by (see [`super::traverse`]).
    ///
    /// # Safety
    /// As [`NodeKernel::children`].
    unsafe fn children_exits(self, node: &WideNode, ray: &NodeRay, limit: f32, dist: &mut [f32; WIDTH]) -> u32;
}

/// Four lanes at a time through glam (SSE2 on x86-64, NEON on aarch64, scalar elsewhere).
#[derive(Clone, Copy, Debug)]
pub struct Portable;

impl NodeKernel for Portable {
    #[inline(always)]
    unsafe fn children(self, node: &WideNode, ray: &NodeRay, limit: f32, dist: &mut [f32; WIDTH]) -> u32 {
        portable_slabs::<false>(node, ray, limit, dist)
    }

    #[inline(always)]
    unsafe fn children_exits(self, node: &WideNode, ray: &NodeRay, limit: f32, dist: &mut [f32; WIDTH]) -> u32 {
        portable_slabs::<true>(node, ray, limit, dist)
    }
}

/// The portable kernel: the entered children, with their entry distances in `dist`, or their
/// exit distances if `EXITS`.
#[inline(always)]
fn portable_slabs<const EXITS: bool>(node: &WideNode, ray: &NodeRay, limit: f32, dist: &mut [f32; WIDTH]) -> u32 {
    {
        let mut mask = 0;
        for half in 0..2 {
            let row = |r: usize| Vec4::from_slice(&node.bounds[r][4 * half..4 * half + 4]);
            let (mut enter, mut exit) = (Vec4::splat(ray.t_min), Vec4::splat(limit));
            for a in 0..3 {
                let (o, inv) = (Vec4::splat(ray.origin[a]), Vec4::splat(-ray.inv_dir[a]));
                let t_near = (o - row(ray.row_index(a, 0))) * inv;
                let t_far = (o - row(ray.row_index(a, 1))) * Vec4::splat(-ray.inv_far[a]);
                enter = Vec4::select(t_near.cmpgt(enter), t_near, enter);
                exit = Vec4::select(t_far.cmplt(exit), t_far, exit);
            }
            mask |= enter.cmple(exit).bitmask() << (4 * half);
            (if EXITS { exit } else { enter }).write_to_slice(&mut dist[4 * half..4 * half + 4]);
        }
        mask
    }
}

#[cfg(target_arch = "x86_64")]
pub use x86::{Avx2, Avx512, Avx512Fused};

#[cfg(target_arch = "x86_64")]
mod x86 {
    use std::arch::x86_64::*;

    use super::super::fused::FusedPlanes;
    use super::{NodeKernel, NodeRay, WIDTH, WideNode};

    /// Eight lanes with AVX2.
    #[derive(Clone, Copy, Debug)]
    pub struct Avx2;

    /// Entry and exit distances of the eight children.
    #[inline(always)]
    unsafe fn slabs(node: &WideNode, ray: &NodeRay, limit: f32) -> (__m256, __m256) {
        // SAFETY (for the whole function): the caller guarantees AVX; every row is 32 bytes
        // inside a node aligned to 64, so the aligned loads are in bounds and aligned.
        unsafe {
            let mut enter = _mm256_set1_ps(ray.t_min);
            let mut exit = _mm256_set1_ps(limit);
            for a in 0..3 {
                let o = _mm256_set1_ps(ray.origin[a]);
                // Negated, so that each row is subtracted from the origin straight from memory
                // (see `child_entry_scalar`); made once per query, outside the walk's loop.
                let inv = _mm256_set1_ps(-ray.inv_dir[a]);
                let inv_far = _mm256_set1_ps(-ray.inv_far[a]);
                // The rows at the byte offsets the ray holds: no index check, no shift per row.
                let near = _mm256_load_ps(ray.row(node, a, 0).as_ptr());
                let far = _mm256_load_ps(ray.row(node, a, 1).as_ptr());
                let t_near = _mm256_mul_ps(_mm256_sub_ps(o, near), inv);
                let t_far = _mm256_mul_ps(_mm256_sub_ps(o, far), inv_far);
                // `max(a, b)` is `a > b ? a : b`, `b` when either is NaN: the scalar rule.
                enter = _mm256_max_ps(t_near, enter);
                exit = _mm256_min_ps(t_far, exit);
            }
            (enter, exit)
        }
    }

    impl NodeKernel for Avx2 {
        const AVX: bool = true;

        #[inline(always)]
        unsafe fn children(self, node: &WideNode, ray: &NodeRay, limit: f32, dist: &mut [f32; WIDTH]) -> u32 {
            // SAFETY: AVX2 is guaranteed by the caller; `dist` holds eight floats.
            unsafe {
                let (enter, exit) = slabs(node, ray, limit);
                _mm256_storeu_ps(dist.as_mut_ptr(), enter);
                _mm256_movemask_ps(_mm256_cmp_ps::<_CMP_LE_OQ>(enter, exit)) as u32
            }
        }

        #[inline(always)]
        unsafe fn children_exits(self, node: &WideNode, ray: &NodeRay, limit: f32, dist: &mut [f32; WIDTH]) -> u32 {
            // SAFETY: as in `children`.
            unsafe {
                let (enter, exit) = slabs(node, ray, limit);
                _mm256_storeu_ps(dist.as_mut_ptr(), exit);
                _mm256_movemask_ps(_mm256_cmp_ps::<_CMP_LE_OQ>(enter, exit)) as u32
            }
        }
    }

    /// Eight lanes with AVX-512 (VL): the comparison lands in a mask register.
    #[derive(Clone, Copy, Debug)]
    pub struct Avx512;

    impl NodeKernel for Avx512 {
        const AVX: bool = true;

        #[inline(always)]
        unsafe fn children(self, node: &WideNode, ray: &NodeRay, limit: f32, dist: &mut [f32; WIDTH]) -> u32 {
            // SAFETY: AVX-512 F and VL are guaranteed by the caller; `dist` holds eight floats.
            unsafe {
                let (enter, exit) = slabs(node, ray, limit);
                _mm256_storeu_ps(dist.as_mut_ptr(), enter);
                _mm256_cmp_ps_mask::<_CMP_LE_OQ>(enter, exit) as u32
            }
        }

        #[inline(always)]
        unsafe fn children_exits(self, node: &WideNode, ray: &NodeRay, limit: f32, dist: &mut [f32; WIDTH]) -> u32 {
            // SAFETY: as in `children`.
            unsafe {
                let (enter, exit) = slabs(node, ray, limit);
                _mm256_storeu_ps(dist.as_mut_ptr(), exit);
                _mm256_cmp_ps_mask::<_CMP_LE_OQ>(enter, exit) as u32
            }
        }
    }

    /// Entry and exit distances of the eight children in the fused form ([`super::super::fused`]),
    /// for a ray to which it applies: a multiply-add per plane, the four entries and the four
    /// exits each reduced in two steps.
    #[inline(always)]
    unsafe fn slabs_fused(node: &WideNode, ray: &NodeRay, p: &FusedPlanes, limit: f32) -> (__m256, __m256) {
        // SAFETY (for the whole function): the caller guarantees AVX2 and FMA; the loads as in
        // `slabs`.
        unsafe {
            // A loop rather than closures: a closure is compiled without the caller's target
            // features, and its intrinsics would become calls.
            let (mut near, mut far) = ([_mm256_setzero_ps(); 3], [_mm256_setzero_ps(); 3]);
            for a in 0..3 {
                let (lo, hi) = (ray.row(node, a, 0).as_ptr(), ray.row(node, a, 1).as_ptr());
                near[a] =
                    _mm256_fmadd_ps(_mm256_load_ps(lo), _mm256_set1_ps(ray.inv_dir[a]), _mm256_set1_ps(p.near[a]));
                far[a] = _mm256_fmadd_ps(_mm256_load_ps(hi), _mm256_set1_ps(ray.inv_far[a]), _mm256_set1_ps(p.far[a]));
            }
            let enter =
                _mm256_max_ps(_mm256_max_ps(near[0], near[1]), _mm256_max_ps(near[2], _mm256_set1_ps(ray.t_min)));
            let exit = _mm256_min_ps(_mm256_min_ps(far[0], far[1]), _mm256_min_ps(far[2], _mm256_set1_ps(limit)));
            (enter, exit)
        }
    }

    /// The fused node test ([`super::super::fused`]) with AVX-512 (VL), for the rays to which
    /// it applies (the dispatch gives the others [`Avx512`]). It carries its ray's constants,
    /// made by [`NodeKernel::for_ray`] at the start of the walk, in the walk's own function, so
    /// that they reach it in registers.
    #[derive(Clone, Copy, Debug)]
    pub struct Avx512Fused(pub FusedPlanes);

    impl NodeKernel for Avx512Fused {
        const AVX: bool = true;

        #[inline(always)]
        unsafe fn for_ray(self, ray: &NodeRay) -> Self {
            // SAFETY: the caller's guarantee: AVX-512 F and VL.
            Avx512Fused(unsafe { FusedPlanes::new_avx512(ray) })
        }

        #[inline(always)]
        unsafe fn children(self, node: &WideNode, ray: &NodeRay, limit: f32, dist: &mut [f32; WIDTH]) -> u32 {
            // SAFETY: AVX-512 F and VL (and FMA) are guaranteed by the caller; `dist` holds eight
            // floats.
            unsafe {
                let (enter, exit) = slabs_fused(node, ray, &self.0, limit);
                _mm256_storeu_ps(dist.as_mut_ptr(), enter);
                _mm256_cmp_ps_mask::<_CMP_LE_OQ>(enter, exit) as u32
            }
        }

        #[inline(always)]
        unsafe fn children_exits(self, node: &WideNode, ray: &NodeRay, limit: f32, dist: &mut [f32; WIDTH]) -> u32 {
            // SAFETY: as in `children`.
            unsafe {
                let (enter, exit) = slabs_fused(node, ray, &self.0, limit);
                _mm256_storeu_ps(dist.as_mut_ptr(), exit);
                _mm256_cmp_ps_mask::<_CMP_LE_OQ>(enter, exit) as u32
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
    use crate::accel::wide::fused::{FusedPlanes, applies_to, child_distances_fused_scalar, child_entry_fused_scalar};
    use crate::accel::wide::isa::Isa;
    use crate::accel::wide::node::{child_entry_scalar, reach};
    use crate::{Aabb, Ray};

    /// Runs `kernel` on the node for every ray and compares with the scalar test, bit for bit.
    fn check(isa: Isa, node: &WideNode, ray: &Ray) -> u32 {
        let r = NodeRay::new(ray);
        let limit = reach(ray.t_max);
        let mut dist = [0.0; WIDTH];
        // SAFETY: each kernel runs only if the processor has its instruction set; the test
        // binary is not compiled with them, but calling the kernel (not inlined then) is sound.
        let mask = unsafe {
            match isa {
                Isa::Portable => Portable.children(node, &r, limit, &mut dist),
                #[cfg(target_arch = "x86_64")]
                Isa::Avx2 => Avx2.children(node, &r, limit, &mut dist),
                #[cfg(target_arch = "x86_64")]
                Isa::Avx512 => Avx512.children(node, &r, limit, &mut dist),
                #[cfg(not(target_arch = "x86_64"))]
                _ => unreachable!(),
            }
        };
        for (slot, &d) in dist.iter().enumerate() {
            let expected = child_entry_scalar(node, slot, &r, limit);
            let got = (mask >> slot & 1 != 0).then_some(d);
            assert_eq!(expected.map(f32::to_bits), got.map(f32::to_bits), "{isa}: slot {slot} of {node:?}, {ray:?}");
        }
        // The same children with their exit distances, as the scalar test's `exit`.
        let mut exits = [0.0; WIDTH];
        // SAFETY: as above.
        let exit_mask = unsafe {
            match isa {
                Isa::Portable => Portable.children_exits(node, &r, limit, &mut exits),
                #[cfg(target_arch = "x86_64")]
                Isa::Avx2 => Avx2.children_exits(node, &r, limit, &mut exits),
                #[cfg(target_arch = "x86_64")]
                Isa::Avx512 => Avx512.children_exits(node, &r, limit, &mut exits),
                #[cfg(not(target_arch = "x86_64"))]
                _ => unreachable!(),
            }
        };
        assert_eq!(exit_mask, mask, "{isa}: {node:?}, {ray:?}");
        for slot in (0..WIDTH).filter(|&slot| mask >> slot & 1 != 0) {
            let mut exit = limit;
            for a in 0..3 {
                let t_far = (r.origin[a] - node.bounds[r.row_index(a, 1)][slot]) * -r.inv_far[a];
                exit = if t_far < exit { t_far } else { exit };
            }
            assert_eq!(exits[slot].to_bits(), exit.to_bits(), "{isa}: slot {slot} of {node:?}, {ray:?}");
        }
        #[cfg(target_arch = "x86_64")]
        if isa == Isa::Avx512 && applies_to(&r) {
            // SAFETY: the AVX-512 instruction set is available.
            let planes = unsafe { FusedPlanes::new_avx512(&r) };
            let reference = FusedPlanes::new(&r);
            for (got, expected) in [(planes.near, reference.near), (planes.far, reference.far)] {
                assert_eq!(got.map(f32::to_bits), expected.map(f32::to_bits), "{ray:?}");
            }
            check_fused(node, ray, &r, &planes, limit);
        }
        mask.count_ones()
    }

    /// The fused kernel against the fused scalar test, bit for bit, entries and exits.
    #[cfg(target_arch = "x86_64")]
    fn check_fused(node: &WideNode, ray: &Ray, r: &NodeRay, planes: &FusedPlanes, limit: f32) {
        let (mut entries, mut exits) = ([0.0; WIDTH], [0.0; WIDTH]);
        let kernel = Avx512Fused(*planes);
        // SAFETY: as in `check`: called only where AVX-512 is available.
        let (mask, exit_mask) = unsafe {
            (kernel.children(node, r, limit, &mut entries), kernel.children_exits(node, r, limit, &mut exits))
        };
        assert_eq!(exit_mask, mask, "fused: {node:?}, {ray:?}");
        for slot in 0..WIDTH {
            let expected = child_entry_fused_scalar(node, slot, r, planes, limit);
            let got = (mask >> slot & 1 != 0).then_some(entries[slot]);
            assert_eq!(expected.map(f32::to_bits), got.map(f32::to_bits), "fused: slot {slot} of {node:?}, {ray:?}");
            if got.is_some() {
                let exit = child_distances_fused_scalar(node, slot, r, planes, limit).1;
                assert_eq!(exits[slot].to_bits(), exit.to_bits(), "fused: slot {slot} of {node:?}, {ray:?}");
            }
        }
    }

    #[test]
    fn every_kernel_agrees_bit_for_bit_with_the_scalar_test() {
        // Integer coordinates and axis-parallel directions of both signs, zeros of both signs,
        // so that origins on planes, rays in faces and flat boxes all occur.
        let mut rng = Pcg32::seed_from_u64(0x1234_5678);
        let mut next = move |n: u32| rng.random_range(0..n);
        let values = [-2.0f32, -1.0, -0.0, 0.0, 0.5, 1.0, 2.0];
        let dirs = [-1.0f32, -0.0, 0.0, 0.3, 1.0];
        for isa in Isa::available() {
            let mut hits = 0;
            for _ in 0..20_000 {
                let children = 1 + next(WIDTH as u32) as usize;
                let t_max = [f32::INFINITY, 1.0, 2.5][next(3) as usize];
                let mut pick = |v: &[f32]| v[next(v.len() as u32) as usize];
                let mut node = WideNode::EMPTY_NODE;
                for slot in 0..children {
                    let a = Vec3::new(pick(&values), pick(&values), pick(&values));
                    let b = Vec3::new(pick(&values), pick(&values), pick(&values));
                    node.set_child(slot, &Aabb::new(a.min(b), a.max(b)), slot as u32, 0);
                }
                let origin = Vec3::new(pick(&values), pick(&values), pick(&values)) * 1.5;
                let dir = Vec3::new(pick(&dirs), pick(&dirs), pick(&dirs));
                // Negative starts too, so that entries of both zeros' signs compete.
                let t_min = [0.0, -0.0, -1.0][next(3) as usize];
                hits += check(isa, &node, &Ray::segment(origin, dir, t_min, t_max));
            }
            // About one box in fourteen is entered: enough of both outcomes.
            assert!(hits > 3_000, "{isa}: {hits}");
        }
    }
}
