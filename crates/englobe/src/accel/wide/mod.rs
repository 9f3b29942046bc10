//! The wide BVH: eight children per node, all eight boxes tested at once with SIMD, converted from
//! the canonical binary [`Bvh`]. Wald, Benthin and Boulos (2008), "Getting Rid of Packets:
//! Efficient SIMD Single-Ray Traversal using Multi-branching BVHs"; the layout and traversal of
//! Embree's `BVH8` (Wald, Woop, Benthin, Johnson and Ernst 2014, "Embree: A Kernel Framework for
//! Efficient CPU Ray Tracing").
//!
//! Two structures share the nodes and the traversal:
//!
//! * [`WideBvh`], behind the [`Accel`] interface like every other structure: leaves hold primitive
//!   references, tested by the query's closure. `--accel bvh-wide`.
//! * [`TriangleBvh`], for triangle meshes: leaves hold the triangles themselves in blocks of four,
//!   tested with a SIMD watertight test. The fast path.
//!
//! Files:
//!
//! * [`node`]: the 256-byte node, child references, the scalar reference slab test.
//! * [`convert`](mod@convert): binary tree ([`binary`]: either kind the builders give) to wide
//!   nodes (largest boxes pulled up first, subtrees in parallel); [`build`](mod@build): the
//!   same wide nodes built straight from the primitives' boxes, without the binary tree;
//!   [`output`]: what both produce (nodes, leaf sinks); `pieces` (inside the crate): their
//!   parallel subtrees stored together once.
//! * [`isa`]: the instruction sets, detected at run time; [`kernels`]: the slab test of eight
//!   children for each; `dispatch` (inside the crate): the per-query choice.
//! * [`traverse`]: the single-ray traversal, generic over kernels and leaves; [`packet`]: the
//!   traversal of packets of up to sixteen rays, with [`packet_rays`], the rays as rows of lanes,
//!   [`packet_kernels`], their node tests,
//!   [`packet_interval`], the test that culls a node's children for a whole packet at once, and
//!   [`packet_triangles`], the triangle test of a whole packet.
//! * [`triangles`]: blocks of four triangles and their SIMD watertight test; [`triangle_bvh`]:
//!   [`TriangleBvh`], with `triangle_leaves` (inside the crate): a ray's leaf tests;
//!   [`triangle_packet`]: its packet queries and batches, with `triangle_packet_leaves` (inside
//!   the crate): a packet's leaf tests, and [`ray_packet`], the rays and hits of a packet as rows
//!   that programs fill and read; [`presplit`]: the large triangles cut before its build, or,
//!   by choice, [`spatial`]: those cut by spatial splits in its top levels.
//! * [`point_query`]: the closest point of the triangles to a point; [`box_query`]: the
//!   triangles overlapping a box.
//! * [`refit`]: the boxes recomputed after the triangles moved, and the SAH cost that says when
//!   to rebuild instead.
//! * [`validate`]: the invariants of both, checked.

mod arena;
pub mod binary;
pub mod box_query;
pub mod build;
pub mod convert;
// The per-query choice of compiled kernels: safe to call only with a structure's own nodes and
// instruction set, so it stays inside the crate.
pub(crate) mod dispatch;
pub mod fused;
pub mod isa;
pub mod kernels;
pub mod node;
pub mod output;
pub mod packet;
pub mod packet_interval;
pub mod packet_kernels;
pub(crate) mod packet_prep;
pub mod packet_rays;
pub mod packet_triangles;
mod pieces;
pub mod point_query;
pub mod presplit;
pub mod ray_packet;
pub mod refit;
pub mod spatial;
pub mod traverse;
pub mod triangle_bvh;
mod triangle_leaves;
pub mod triangle_packet;
mod triangle_packet_leaves;
mod triangle_query;
pub mod triangles;
pub mod validate;

pub use isa::{Isa, IsaUnavailable};
pub use point_query::ClosestPoint;
pub use ray_packet::{PacketHits, RayPacket};
pub use refit::{RefitError, RefitReport};
pub use triangle_bvh::{TriangleBvh, TriangleBvhOptions};

use convert::{ConvertOptions, LeafSink, convert};
use node::{EMPTY, MAX_LEAF_ITEMS, NodeRay, WIDTH, WideNode, is_leaf, reach};
use traverse::Leaves;

use super::bvh::{BinnedSah, Bvh};
use super::{Accel, Counters, Hit, HitRecord, LEAF_SIZE_BUCKETS, StructureStats};
use crate::PrimHit;
use crate::{Aabb, Ray};

/// A wide BVH whose leaves hold primitive references, queried through closures like every
/// [`Accel`]. Built from the binned SAH tree; leaves are the binary tree's.
#[derive(Clone, Debug)]
pub struct WideBvh {
    nodes: Vec<WideNode>,
    prim_indices: Vec<u32>,
    depth: u32,
    bounds: Aabb,
    isa: Isa,
}

/// Stores leaves as ranges of primitive references.
struct References(Vec<u32>);

impl LeafSink for References {
    fn max_prims(&self) -> usize {
        MAX_LEAF_ITEMS
    }

    fn leaf(&mut self, prims: &[u32]) -> (u32, u8) {
        let first = self.0.len() as u32;
        self.0.extend_from_slice(prims);
        (first, prims.len() as u8)
    }

    type Item = u32;

    fn split(&self) -> Self {
        References(Vec::new())
    }

    fn into_items(self) -> Vec<u32> {
        self.0
    }

    fn append(&mut self, items: &[u32]) -> u32 {
        let first = self.0.len() as u32;
        self.0.extend_from_slice(items);
        first
    }
}

impl WideBvh {
    /// The binned SAH tree over the boxes, made wide.
    pub fn build(boxes: &[Aabb]) -> Self {
        Self::from_bvh(&BinnedSah::default().build(boxes))
    }

    /// Any binary tree made wide, its leaves kept (split if larger than a leaf reference holds).
    pub fn from_bvh(bvh: &Bvh) -> Self {
        let mut sink = References(Vec::with_capacity(bvh.prim_indices().len()));
        let layout = convert(bvh, ConvertOptions { collapse: 0 }, &mut sink);
        WideBvh {
            nodes: layout.nodes,
            prim_indices: sink.0,
            depth: layout.depth,
            bounds: bvh.bounds(),
            isa: Isa::best(),
        }
    }

    /// The instruction set queries run with.
    pub fn isa(&self) -> Isa {
        self.isa
    }

    /// Runs queries with `isa` from now on, if the processor has it.
    pub fn set_isa(&mut self, isa: Isa) -> Result<(), IsaUnavailable> {
        if !isa.is_available() {
            return Err(IsaUnavailable(isa));
        }
        self.isa = isa;
        Ok(())
    }

    /// The nodes (the root is node 0).
    pub fn nodes(&self) -> &[WideNode] {
        &self.nodes
    }

    /// The leaves' primitive references.
    pub fn prim_indices(&self) -> &[u32] {
        &self.prim_indices
    }

    /// Wide nodes on the longest path from the root to a leaf.
    pub fn depth(&self) -> u32 {
        self.depth
    }
}

/// A query's view of the primitive references, its closure and its closest hit so far.
struct ClosureLeaves<'a, F> {
    prims: &'a [u32],
    record: HitRecord,
    test: F,
}

impl<C: Counters, F: FnMut(u32, &Ray) -> Option<PrimHit>> Leaves<C> for ClosureLeaves<'_, F> {
    /// Nothing: the closure tests the ray itself.
    type Prepared = ();

    #[inline(always)]
    fn prepare<K: kernels::NodeKernel>(&self) {}

    #[inline(always)]
    fn closest(&mut self, _: &(), first: u32, count: u32, counters: &mut C) {
        for &prim in &self.prims[first as usize..(first + count) as usize] {
            counters.exact_test();
            if let Some(hit) = (self.test)(prim, &self.record.ray) {
                self.record.offer(prim, hit);
            }
        }
    }

    #[inline(always)]
    fn t_max(&self) -> f32 {
        self.record.ray.t_max
    }

    #[inline(always)]
    fn any(&mut self, _: &(), first: u32, count: u32, counters: &mut C) -> bool {
        for &prim in &self.prims[first as usize..(first + count) as usize] {
            counters.exact_test();
            if (self.test)(prim, &self.record.ray).is_some() {
                return true;
            }
        }
        false
    }
}

impl WideBvh {
    /// The single-ray closest-hit walk of the subtree of node `start` (an interior node) from
    /// `record`: its ray, valid, and its closest hit so far; returns the record at the end. A
    /// whole query starts at the root; a packet walk hands its rays over here when they go apart
    /// (see [`packet::PacketLeaves::alone`]).
    #[inline]
    pub(crate) fn closest_from<C: Counters>(
        &self,
        start: u32,
        record: HitRecord,
        counters: &mut C,
        intersect: impl FnMut(u32, &Ray) -> Option<PrimHit>,
    ) -> HitRecord {
        let node_ray = NodeRay::new(&record.ray);
        let mut leaves = ClosureLeaves { prims: &self.prim_indices, record, test: intersect };
        dispatch::closest(self.isa, &self.nodes, self.depth, start, &node_ray, &mut leaves, counters);
        leaves.record
    }

    /// The single-ray any-hit walk of the subtree of node `start` (see [`WideBvh::closest_from`]).
    #[inline]
    pub(crate) fn any_from<C: Counters>(
        &self,
        start: u32,
        ray: &Ray,
        counters: &mut C,
        mut occludes: impl FnMut(u32, &Ray) -> bool,
    ) -> bool {
        let test = |prim: u32, r: &Ray| occludes(prim, r).then_some(PrimHit::at(0.0));
        let mut leaves = ClosureLeaves { prims: &self.prim_indices, record: HitRecord::new(*ray), test };
        dispatch::any(
            self.isa,
            &self.nodes,
            self.depth,
            start,
            &NodeRay::new(ray),
            reach(ray.t_max),
            &mut leaves,
            counters,
        )
    }
}

impl Accel for WideBvh {
    fn bounds(&self) -> Aabb {
        self.bounds
    }

    #[inline]
    fn closest_hit<C: Counters>(
        &self,
        ray: &Ray,
        counters: &mut C,
        intersect: impl FnMut(u32, &Ray) -> Option<PrimHit>,
    ) -> Option<Hit> {
        if !ray.is_valid() || self.nodes.is_empty() {
            return None;
        }
        self.closest_from(0, HitRecord::new(*ray), counters, intersect).hit
    }

    #[inline]
    fn any_hit<C: Counters>(&self, ray: &Ray, counters: &mut C, occludes: impl FnMut(u32, &Ray) -> bool) -> bool {
        if !ray.is_valid() || self.nodes.is_empty() {
            return false;
        }
        self.any_from(0, ray, counters, occludes)
    }

    fn stats(&self) -> StructureStats {
        let mut leaf_sizes = [0; LEAF_SIZE_BUCKETS];
        let mut leaves = 0;
        for node in &self.nodes {
            for slot in (0..WIDTH).filter(|&s| node.children[s] != EMPTY && is_leaf(node.children[s])) {
                leaf_sizes[(node.counts[slot] as usize).clamp(1, LEAF_SIZE_BUCKETS) - 1] += 1;
                leaves += 1;
            }
        }
        StructureStats {
            nodes: self.nodes.len(),
            leaves,
            depth: self.depth as usize,
            prim_refs: self.prim_indices.len(),
            memory_bytes: std::mem::size_of::<Self>()
                + std::mem::size_of_val(self.nodes.as_slice())
                + std::mem::size_of_val(self.prim_indices.as_slice()),
            sah_cost: None,
            leaf_sizes,
        }
    }
}

#[cfg(test)]
mod tests {
    use glam::Vec3;

    use super::traverse::INLINE_DEPTH;
    use super::*;
    use crate::accel::NoCount;
    use crate::accel::bvh::{BuildKind, BuildNode, BuildTree};
    use crate::accel::reference::BruteForce;
    use crate::shapes::AaBox;

    /// A chain: interior node `k` holds leaf `k` and node `k + 1`, so the wide tree is about
    /// `n / 7` nodes deep, and queries use the per-thread stack instead of the inline one.
    fn chain(n: u32) -> (Vec<Aabb>, Bvh) {
        let boxes: Vec<Aabb> =
            (0..n).map(|i| Aabb::new(Vec3::new(i as f32, 0.0, 0.0), Vec3::new(i as f32 + 0.5, 1.0, 1.0))).collect();
        let mut nodes: Vec<BuildNode> = boxes
            .iter()
            .enumerate()
            .map(|(i, &b)| BuildNode { bounds: b, kind: BuildKind::Leaf { first: i as u32, count: 1 } })
            .collect();
        for i in 0..n - 1 {
            let bounds = Aabb::new(Vec3::new(i as f32, 0.0, 0.0), Vec3::new(n as f32, 1.0, 1.0));
            let next = if i + 1 == n - 1 { n - 1 } else { n + i + 1 };
            nodes.push(BuildNode { bounds, kind: BuildKind::Interior { children: [i, next], count: n - i } });
        }
        let bvh = BuildTree { nodes, prims: (0..n).collect(), root: n }.into_bvh();
        (boxes, bvh)
    }

    #[test]
    fn trees_deeper_than_the_inline_stack_agree_with_brute_force() {
        let (boxes, bvh) = chain(600);
        let mut wide = WideBvh::from_bvh(&bvh);
        crate::accel::Validate::validate(&wide, &boxes, None).unwrap();
        assert!(wide.depth() as usize > INLINE_DEPTH, "depth {}", wide.depth());
        let shapes: Vec<AaBox> = boxes.iter().map(|b| AaBox::new(b.min, b.max)).collect();
        let test = |i: u32, r: &Ray| crate::shapes::Intersect::intersect(&shapes[i as usize], r);
        let brute = BruteForce::build(&boxes);
        let rays: Vec<Ray> = (0..50)
            .flat_map(|k| {
                let y = 0.1 + k as f32 * 0.015;
                [Ray::new(Vec3::new(700.0, y, 0.5), -Vec3::X), Ray::new(Vec3::new(-1.0, y, 0.5), Vec3::X)]
            })
            .chain([Ray::segment(Vec3::new(300.25, 0.5, 0.5), Vec3::X, 0.0, 3.0)])
            .collect();
        for isa in Isa::available() {
            wide.set_isa(isa).unwrap();
            for r in &rays {
                let expected = brute.closest_hit(r, &mut NoCount, test);
                assert_eq!(wide.closest_hit(r, &mut NoCount, test), expected, "{isa}: {r:?}");
                assert!(expected.is_some());
                assert!(wide.any_hit(r, &mut NoCount, |i, r| test(i, r).is_some()), "{isa}: {r:?}");
            }
        }
    }
}
