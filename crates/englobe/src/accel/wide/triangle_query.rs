//! The any-hit query of a [`TriangleBvh`] compiled whole with the structure's instruction set
//! ([`dispatch::ray_query`]): the node test's constants, the leaves' state and the walk in one
//! function, where the walk used to be a call of its own, handed its ray constants and its leaves'
//! state in memory by the query around it, which then made its own constants again (the call had
//! taken every vector register). About 30 fewer instructions per random any-hit ray (4-5 %), and
//! 1.0-1.6 % faster, under each of three code placements (`scripts/ab-bench.sh`, see
//! `docs/performance.md`). The query's own methods ([`TriangleBvh::any_hit_filtered`]) check the
//! ray; `any_hit_of_valid` here tests the root's box and runs the rest.
//!
//! The closest-hit query stays a call of the walk ([`dispatch::closest`]): compiled whole the same
//! way, it ran 25-35 more instructions per ray and 0-4.5 % slower, the compiler making the node
//! test's eight-wide constants again every time the walk came back from a leaf to a node.

use super::dispatch::{self, RayQuery};
use super::fused;
use super::isa::Isa;
use super::kernels::NodeKernel;
use super::node::{NodeRay, WideNode, reach};
use super::traverse;
use super::triangle_bvh::TriangleBvh;
use super::triangle_leaves::{self, AnyWalk, TriangleLeaves};
use crate::Ray;
use crate::accel::{Counters, Hit, HitFilter};

impl TriangleBvh {
    /// [`TriangleBvh::any_hit_filtered`] of a ray the caller checked with [`Ray::is_valid`].
    ///
    /// Always inlined: its callers' loops keep the ray in registers, and the compiler stopped
    /// inlining it once the dispatch had a fused copy to choose.
    #[inline(always)]
    pub(crate) fn any_hit_of_valid<C: Counters, F: HitFilter<Hit>>(
        &self,
        ray: &Ray,
        counters: &mut C,
        filter: F,
    ) -> bool {
        debug_assert!(ray.is_valid());
        if self.nodes().is_empty() {
            return false;
        }
        // The root's box first: a ray that passes beside it costs no more.
        counters.box_tests(1);
        if !self.may_enter(ray) {
            return false;
        }
        dispatch::ray_query(self.isa(), Any { bvh: self, ray, counters, filter })
    }
}

/// Whether a valid ray hits a triangle whose hit `filter` accepts
/// ([`TriangleBvh::any_hit_filtered`]).
struct Any<'a, C, F> {
    bvh: &'a TriangleBvh,
    ray: &'a Ray,
    counters: &'a mut C,
    filter: F,
}

impl<C: Counters, F: HitFilter<Hit>> RayQuery for Any<'_, C, F> {
    type Output = bool;

    #[inline(always)]
    fn fused(&self) -> bool {
        fused::applies(self.ray.origin_a(), self.ray.inv_dir_a(), self.ray.t_min)
    }

    #[inline(always)]
    unsafe fn run<K: NodeKernel>(self, kernel: K) -> bool {
        let Any { bvh, ray, counters, filter } = self;
        debug_assert!(ray.is_valid() && !bvh.nodes().is_empty());
        // SAFETY: `run`'s guarantee.
        let mut walk = unsafe { TreeWalk::new(kernel, bvh, ray, counters) };
        triangle_leaves::any_hit_with(bvh.blocks(), ray, ray.t_max, filter, &mut walk)
    }
}

/// An any-hit walk of the whole tree with `kernel`, compiled into the query that makes it.
struct TreeWalk<'a, K, C> {
    kernel: K,
    isa: Isa,
    nodes: &'a [WideNode],
    depth: u32,
    ray: NodeRay,
    /// Where a box may begin and still be entered by an any-hit walk.
    limit: f32,
    counters: &'a mut C,
}

impl<'a, K: NodeKernel, C: Counters> TreeWalk<'a, K, C> {
    /// The walks of `ray` in `bvh`.
    ///
    /// # Safety
    /// As [`NodeKernel::children`]: the walks run compiled with the kernel's target features, on
    /// a processor that has them.
    #[inline(always)]
    unsafe fn new(kernel: K, bvh: &'a TriangleBvh, ray: &Ray, counters: &'a mut C) -> Self {
        TreeWalk {
            kernel,
            isa: bvh.isa(),
            nodes: bvh.nodes(),
            depth: bvh.depth(),
            ray: NodeRay::new(ray),
            limit: reach(ray.t_max),
            counters,
        }
    }
}

impl<F: HitFilter<Hit>, K: NodeKernel, C: Counters> AnyWalk<F> for TreeWalk<'_, K, C> {
    #[inline(always)]
    fn walk(&mut self, leaves: &mut TriangleLeaves<'_, F>) -> bool {
        // SAFETY: `TreeWalk::new`'s guarantee; the tree's interior references index its nodes,
        // as the builders make them.
        unsafe { traverse::any(self.kernel, self.nodes, self.depth, 0, &self.ray, self.limit, leaves, self.counters) }
    }

    #[inline(always)]
    fn walk_again(&mut self, leaves: &mut TriangleLeaves<'_, F>) -> bool {
        dispatch::any(self.isa, self.nodes, self.depth, 0, &self.ray, self.limit, leaves, self.counters)
    }
}

#[cfg(test)]
mod tests {
    use glam::Vec3;

    use super::super::triangle_bvh::TriangleBvhOptions;
    use super::super::triangle_leaves::DEFERRED;
    use super::*;
    use crate::accel::WorkCounts;

    /// `n` triangles in fans around the vertical line through the origin, a fan every six, each at
    /// its own height: a ray down that line meets their shared vertices, every lane undecided.
    fn fans(n: usize) -> Vec<[Vec3; 3]> {
        let at = |k: usize, z: f32| {
            let a = k as f32 * std::f32::consts::TAU / 6.0;
            Vec3::new(a.cos(), a.sin(), z)
        };
        (0..n)
            .map(|k| {
                let z = -0.25 * (k / 6) as f32;
                [Vec3::new(0.0, 0.0, z), at(k, z), at(k + 1, z)]
            })
            .collect()
    }

    #[test]
    fn an_any_hit_walk_that_meets_too_many_undecided_lanes_is_made_again_on_every_instruction_set() {
        for n in [3, 8, 9, 20, 41] {
            let tris = fans(n);
            let options =
                TriangleBvhOptions { presplit_percent: 0, spatial_levels: 0, ..TriangleBvhOptions::default() };
            let mut bvh = TriangleBvh::build_with(n, |i| tris[i as usize], options);
            let ray = Ray::new(Vec3::Z, -Vec3::Z);
            for isa in Isa::available() {
                bvh.set_isa(isa).expect("available");
                assert!(bvh.any_hit(&ray, &mut WorkCounts::default()), "{isa}, {n} triangles");
                // With every hit refused, each walk tests every triangle once (their boxes all
                // hold the line); one that notes more lanes than its list holds is made again.
                let mut counts = WorkCounts::default();
                assert!(!bvh.any_hit_filtered(&ray, &mut counts, |_: &Hit| false), "{isa}, {n} triangles");
                let walks = if n > DEFERRED { 2 } else { 1 };
                assert_eq!(counts.exact_tests, (walks * n) as u64, "{isa}, {n} triangles");
            }
        }
    }
}
