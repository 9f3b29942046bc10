//! The seed report's builder, exactly as it describes it: Deneux and Joniaux (2009),
//! "Pré-détermination des objets impactés par un rayon (accélération du rendu)", Université de
//! Liège, section 5.3.
//!
//! 1. One tight box per object: every primitive is a leaf of its own.
//! 2. The leaves are sorted on `center.x + center.y + center.z` of their boxes (the report inserts
//!    them one by one into a sorted list; a stable sort with the primitive index breaking ties
//!    gives the same order, deterministically).
//! 3. Level by level, neighbours in that order are paired under a parent box: the first with the
//!    second, the third with the fourth, and so on; an odd one out is promoted alone to the next
//!    level. This repeats until a single root remains.
//!
//! The tree is therefore balanced by construction: its depth is `ceil(log2(n))` for `n`
//! primitives. Its quality depends entirely on how well the diagonal key keeps neighbours in space
//! together, which is the point of measuring it.

use crate::Aabb;
use crate::accel::bvh::{BuildKind, BuildNode, BuildTree, Bvh};

/// The seed report's bottom-up pairing builder.
#[derive(Clone, Copy, Debug, Default)]
pub struct SeedPairing;

impl SeedPairing {
    /// Builds the tree over the primitives' boxes (primitive `i` has box `boxes[i]`).
    pub fn build(boxes: &[Aabb]) -> Bvh {
        Self::build_tree(boxes).into_bvh()
    }

    /// The report's sort key of a box: the sum of its centre's coordinates.
    #[inline]
    pub fn key(bounds: &Aabb) -> f32 {
        let c = bounds.center();
        c.x + c.y + c.z
    }

    /// The tree before layout: leaves first (in key order), then each level's parents, root last.
    pub fn build_tree(boxes: &[Aabb]) -> BuildTree {
        let n = boxes.len();
        if n == 0 {
            return BuildTree::default();
        }
        let keys: Vec<f32> = boxes.iter().map(Self::key).collect();
        let mut order: Vec<u32> = (0..n as u32).collect();
        // `total_cmp` orders every float, NaN included, so the sort never panics; the index
        // breaks ties as the report's insertion sort (which inserts after equal keys) does.
        order.sort_by(|&a, &b| keys[a as usize].total_cmp(&keys[b as usize]).then(a.cmp(&b)));

        let mut nodes: Vec<BuildNode> = Vec::with_capacity(2 * n - 1);
        nodes.extend(order.iter().enumerate().map(|(slot, &prim)| BuildNode {
            bounds: boxes[prim as usize],
            kind: BuildKind::Leaf { first: slot as u32, count: 1 },
        }));
        let mut level: Vec<u32> = (0..n as u32).collect();
        while level.len() > 1 {
            let mut parents = Vec::with_capacity(level.len().div_ceil(2));
            for pair in level.chunks(2) {
                match *pair {
                    [left, right] => {
                        let bounds = nodes[left as usize].bounds.union(&nodes[right as usize].bounds);
                        parents.push(nodes.len() as u32);
                        let count = nodes[left as usize].prims_under() + nodes[right as usize].prims_under();
                        nodes.push(BuildNode { bounds, kind: BuildKind::Interior { children: [left, right], count } });
                    }
                    // The odd one out goes up alone.
                    [alone] => parents.push(alone),
                    _ => unreachable!("chunks(2) yields one or two nodes"),
                }
            }
            level = parents;
        }
        BuildTree { nodes, prims: order, root: level[0] }
    }
}

#[cfg(test)]
mod tests {
    use glam::Vec3;

    use super::*;

    fn cube(c: Vec3, r: f32) -> Aabb {
        Aabb::new(c - Vec3::splat(r), c + Vec3::splat(r))
    }

    #[test]
    fn leaves_follow_the_diagonal_key() {
        // Keys: 6, -3, 0.3, 3 -> order 1, 2, 3, 0.
        let boxes = [
            cube(Vec3::new(2.0, 2.0, 2.0), 0.1),
            cube(Vec3::new(-1.0, -1.0, -1.0), 0.1),
            cube(Vec3::new(0.1, 0.1, 0.1), 0.1),
            cube(Vec3::new(3.0, 0.0, 0.0), 0.1),
        ];
        let bvh = SeedPairing::build(&boxes);
        assert_eq!(bvh.prim_indices(), &[1, 2, 3, 0]);
        // Two pairs under the root: (1, 2) and (3, 0).
        let n = bvh.nodes();
        assert_eq!(n.len(), 7);
        assert_eq!(n[1].bounds(), boxes[1].union(&boxes[2]));
        assert_eq!(n[n[0].index as usize].bounds(), boxes[3].union(&boxes[0]));
        assert_eq!(bvh.depth(), 2);
    }

    #[test]
    fn the_odd_one_out_is_promoted_alone() {
        // Five leaves on the diagonal: level 1 = (0 1) (2 3) 4; level 2 = ((0 1) (2 3)) 4.
        let boxes: Vec<Aabb> = (0..5).map(|i| cube(Vec3::splat(i as f32), 0.25)).collect();
        let tree = SeedPairing::build_tree(&boxes);
        assert_eq!(tree.nodes.len(), 9);
        let root = tree.nodes[tree.root as usize];
        let BuildKind::Interior { children: [left, right], .. } = root.kind else { panic!("the root is interior") };
        assert_eq!(right, 4, "leaf 4 went up alone to pair with the root's left subtree");
        assert_eq!(tree.nodes[left as usize].bounds, boxes[0].union(&boxes[3]));
        let bvh = tree.into_bvh();
        assert_eq!(bvh.depth(), 3);
        assert_eq!(bvh.prim_indices(), &[0, 1, 2, 3, 4]);
    }

    #[test]
    fn equal_keys_keep_the_primitive_order() {
        let boxes = vec![cube(Vec3::ZERO, 1.0); 6];
        assert_eq!(SeedPairing::build(&boxes).prim_indices(), &[0, 1, 2, 3, 4, 5]);
        // Same key, different places: (1, 0, 0) and (0, 1, 0) tie; the lower index comes first.
        let boxes = [cube(Vec3::Y, 0.1), cube(Vec3::X, 0.1)];
        assert_eq!(SeedPairing::build(&boxes).prim_indices(), &[0, 1]);
    }

    #[test]
    fn depth_is_the_ceiling_of_log2() {
        for n in [1usize, 2, 3, 4, 5, 7, 8, 9, 100, 1000, 1025] {
            let boxes: Vec<Aabb> = (0..n).map(|i| cube(Vec3::new(i as f32, 0.0, 0.0), 0.4)).collect();
            let bvh = SeedPairing::build(&boxes);
            assert_eq!(bvh.depth(), (n as f64).log2().ceil() as u32, "n = {n}");
            assert_eq!(bvh.nodes().len(), 2 * n - 1);
        }
    }

    #[test]
    fn nan_boxes_do_not_panic() {
        let boxes = [cube(Vec3::new(f32::NAN, 0.0, 0.0), 1.0), cube(Vec3::ZERO, 1.0), Aabb::EMPTY];
        let bvh = SeedPairing::build(&boxes);
        assert_eq!(bvh.nodes().len(), 5);
    }
}
