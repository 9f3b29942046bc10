//! The triangles of a [`TriangleBvh`] that overlap a box: what Embree's `rtcCollide` and parry's
//! `intersect_aabb` give a physics engine's broad phase or an editor's selection, but exact: a
//! triangle counts if the triangle itself meets the box (the separating axis test of
//! Akenine-Möller 2001, [`triangle_overlaps_box`]), not merely its bounds.
//!
//! The walk enters every child whose box overlaps the query box (a comparison of planes, exact);
//! that test never rejects a box holding a triangle the exact test accepts, because the exact
//! test begins with the same comparison on the triangle's own box. So the answer is brute force's.

use super::TriangleBvh;
use super::node::{EMPTY, WIDTH, index_of, is_leaf};
use super::triangles::{LANES, UNUSED};
use crate::Aabb;
use crate::shapes::triangle_overlaps_box;

/// Whether the closed boxes `a` and `b` share a point.
#[inline(always)]
fn boxes_overlap(a: &Aabb, b: &Aabb) -> bool {
    a.min.cmple(b.max).all() && b.min.cmple(a.max).all()
}

impl TriangleBvh {
    /// Calls `found(triangle)` for every stored triangle that overlaps `query` (boundaries
    /// included), in no particular order, each once.
    pub fn for_each_triangle_in_box(&self, query: &Aabb, found: impl FnMut(u32)) {
        if self.cut {
            // A cut triangle may be met in several leaves: gathered, then reported once each.
            let mut all = Vec::new();
            self.walk_box(query, |t| all.push(t));
            all.sort_unstable();
            all.dedup();
            all.into_iter().for_each(found);
        } else {
            self.walk_box(query, found);
        }
    }

    /// Calls `found` for every triangle overlapping `query` in every leaf that holds it.
    fn walk_box(&self, query: &Aabb, mut found: impl FnMut(u32)) {
        if self.nodes.is_empty() || !boxes_overlap(&self.bounds, query) {
            return;
        }
        let mut stack: Vec<(u32, u32)> = Vec::with_capacity((WIDTH - 1) * self.depth as usize + 1);
        stack.push((0, 0));
        while let Some((reference, count)) = stack.pop() {
            if is_leaf(reference) {
                let first = index_of(reference) as usize;
                for block in &self.blocks[first..first + count as usize] {
                    for lane in 0..LANES {
                        let prim = block.ids[lane];
                        if prim != UNUSED && triangle_overlaps_box(block.vertices(lane), query) {
                            found(prim);
                        }
                    }
                }
                continue;
            }
            let node = &self.nodes[reference as usize];
            for slot in 0..WIDTH {
                let c = node.children[slot];
                if c != EMPTY && boxes_overlap(&node.child_bounds(slot), query) {
                    stack.push((c, node.counts[slot] as u32));
                }
            }
        }
    }

    /// The stored triangles that overlap `query` (boundaries included), in increasing order.
    ///
    /// ```
    /// use englobe::{Aabb, TriangleBvh, Vec3};
    ///
    /// let far = Vec3::splat(10.0);
    /// let bvh = TriangleBvh::from_triangles(&[[far, far + Vec3::X, far + Vec3::Y], [Vec3::ZERO, Vec3::X, Vec3::Y]]);
    /// assert_eq!(bvh.triangles_in_box(&Aabb::new(Vec3::splat(-1.0), Vec3::splat(0.5))), vec![1]);
    /// ```
    pub fn triangles_in_box(&self, query: &Aabb) -> Vec<u32> {
        let mut out = Vec::new();
        self.for_each_triangle_in_box(query, |t| out.push(t));
        out.sort_unstable();
        out
    }
}
