//! The surface area heuristic (SAH) applied after the fact: subtrees that would cost less as one
//! leaf are collapsed into one. Bottom-up builders ([`super::Ploc`]) make one leaf per primitive;
//! this post-pass gives their trees the leaves a top-down SAH builder would have chosen, so that
//! trees from all builders compare. The decision is the exact optimum for the tree's shape: a
//! node's cost is the cheaper of a leaf over its subtree's primitives (when they are at most
//! `max_leaf`) and `C_t` plus its children's costs, computed children first. Karras and Aila
//! (2013), "Fast Parallel Construction of High-Quality Bounding Volume Hierarchies" (High
//! Performance Graphics) end their builder with the same pass over trees of one primitive per
//! leaf.
//!
//! Every walk uses an explicit stack: a degenerate tree (a chain) is no problem.

use crate::accel::bvh::layout::{BuildKind, BuildNode, BuildTree};
use crate::accel::bvh::stats::{SAH_INTERSECTION_COST, SAH_TRAVERSAL_COST};

/// `tree` with every subtree of at most `max_leaf` primitives that costs less as a leaf collapsed
/// into a leaf; the leaves' primitive references are reordered so that each leaf's are
/// contiguous. Nodes not reachable from the root are dropped.
pub fn collapse_leaves(tree: &BuildTree, max_leaf: usize) -> BuildTree {
    if tree.nodes.is_empty() {
        return BuildTree::default();
    }
    let nodes = &tree.nodes;
    // Nodes in depth-first order from the root: parents before children.
    let mut order = Vec::with_capacity(nodes.len());
    let mut stack = vec![tree.root];
    while let Some(id) = stack.pop() {
        order.push(id);
        if let BuildKind::Interior { children, .. } = nodes[id as usize].kind {
            stack.extend(children);
        }
    }
    // Probabilities are relative to the root's area; if it has none (everything on one point or
    // segment), every node counts as reached, as in `Bvh::sah_cost`.
    let root_area = nodes[tree.root as usize].bounds.surface_area() as f64;
    let weight = |n: &BuildNode| if root_area > 0.0 { n.bounds.surface_area() as f64 } else { 1.0 };
    // Children before parents: each node's best cost, and whether it becomes a leaf.
    let mut cost = vec![0f64; nodes.len()];
    let mut leaf = vec![false; nodes.len()];
    for &id in order.iter().rev() {
        let id = id as usize;
        let w = weight(&nodes[id]);
        match nodes[id].kind {
            BuildKind::Leaf { count: c, .. } => {
                cost[id] = SAH_INTERSECTION_COST as f64 * c as f64 * w;
                leaf[id] = true;
            }
            BuildKind::Interior { children: [a, b], count } => {
                let (a, b) = (a as usize, b as usize);
                let split = SAH_TRAVERSAL_COST as f64 * w + cost[a] + cost[b];
                let as_leaf = SAH_INTERSECTION_COST as f64 * count as f64 * w;
                leaf[id] = count as usize <= max_leaf && as_leaf <= split;
                cost[id] = if leaf[id] { as_leaf } else { split };
            }
        }
    }

    // Lay the tree out again, parents first; a collapsed subtree gathers its primitives.
    let mut out = BuildTree { nodes: Vec::new(), prims: Vec::with_capacity(tree.prims.len()), root: 0 };
    // (node, parent in `out` and which of its children this is)
    let mut stack: Vec<(u32, Option<(usize, usize)>)> = vec![(tree.root, None)];
    let mut gather = Vec::new();
    while let Some((id, parent)) = stack.pop() {
        let here = out.nodes.len() as u32;
        if let Some((p, which)) = parent
            && let BuildKind::Interior { children, .. } = &mut out.nodes[p].kind
        {
            children[which] = here;
        }
        let node = &nodes[id as usize];
        if leaf[id as usize] {
            let first = out.prims.len() as u32;
            gather.push(id);
            while let Some(g) = gather.pop() {
                match nodes[g as usize].kind {
                    BuildKind::Leaf { first, count } => {
                        out.prims.extend_from_slice(&tree.prims[first as usize..(first + count) as usize]);
                    }
                    BuildKind::Interior { children: [a, b], .. } => gather.extend([b, a]),
                }
            }
            let count = out.prims.len() as u32 - first;
            out.nodes.push(BuildNode { bounds: node.bounds, kind: BuildKind::Leaf { first, count } });
        } else if let BuildKind::Interior { children: [a, b], count } = node.kind {
            out.nodes.push(BuildNode { bounds: node.bounds, kind: BuildKind::Interior { children: [0, 0], count } });
            stack.push((b, Some((here as usize, 1))));
            stack.push((a, Some((here as usize, 0))));
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use glam::Vec3;

    use super::*;
    use crate::Aabb;
    use crate::accel::bvh::validate::validate_bvh;

    fn unit_at(x: f32) -> Aabb {
        Aabb::new(Vec3::new(x, 0.0, 0.0), Vec3::new(x + 1.0, 1.0, 1.0))
    }

    /// A balanced tree of single-primitive leaves over `boxes`, built bottom-up (root last), its
    /// primitive references in reverse order.
    fn pairs(boxes: &[Aabb]) -> BuildTree {
        let n = boxes.len() as u32;
        let mut nodes: Vec<BuildNode> = boxes
            .iter()
            .enumerate()
            .map(|(i, b)| BuildNode { bounds: *b, kind: BuildKind::Leaf { first: n - 1 - i as u32, count: 1 } })
            .collect();
        let mut level: Vec<u32> = (0..boxes.len() as u32).collect();
        while level.len() > 1 {
            level = level
                .chunks(2)
                .map(|c| match *c {
                    [a, b] => {
                        let bounds = nodes[a as usize].bounds.union(&nodes[b as usize].bounds);
                        let count = nodes[a as usize].prims_under() + nodes[b as usize].prims_under();
                        nodes.push(BuildNode { bounds, kind: BuildKind::Interior { children: [a, b], count } });
                        nodes.len() as u32 - 1
                    }
                    [a] => a,
                    _ => unreachable!(),
                })
                .collect();
        }
        BuildTree { nodes, prims: (0..boxes.len() as u32).rev().collect(), root: level[0] }
    }

    #[test]
    fn overlapping_primitives_collapse_and_separate_ones_do_not() {
        // Four copies of one box, and four boxes far apart.
        let same = vec![unit_at(0.0); 4];
        let tree = collapse_leaves(&pairs(&same), 8);
        assert_eq!(tree.nodes.len(), 1);
        assert_eq!(tree.nodes[0].kind, BuildKind::Leaf { first: 0, count: 4 });
        let apart: Vec<Aabb> = (0..4).map(|i| unit_at(10.0 * i as f32)).collect();
        let before = pairs(&apart);
        let after = collapse_leaves(&before, 8);
        assert_eq!(after.nodes.len(), 7);
        let bvh = after.into_bvh();
        let q = validate_bvh(&bvh, &apart).unwrap();
        assert_eq!(q.sah_cost, before.into_bvh().sah_cost());
    }

    #[test]
    fn the_cost_never_rises_and_leaves_respect_the_limit() {
        // Boxes overlapping in small groups along a line.
        let boxes: Vec<Aabb> = (0..100).map(|i| unit_at((i / 3) as f32 * 1.5 + (i % 3) as f32 * 0.01)).collect();
        let before = pairs(&boxes);
        let cost_before = before.clone().into_bvh().sah_cost();
        for max_leaf in [1, 2, 4, 8] {
            let bvh = collapse_leaves(&before, max_leaf).into_bvh();
            let q = validate_bvh(&bvh, &boxes).unwrap();
            assert!(q.max_leaf <= max_leaf && q.tight, "{q:?}");
            assert!(q.sah_cost <= cost_before * (1.0 + 1e-6), "{} > {cost_before}", q.sah_cost);
            if max_leaf >= 4 {
                assert!(q.sah_cost < cost_before && q.leaves < 100, "{q:?}");
            }
        }
    }

    #[test]
    fn a_deep_chain_is_collapsed_without_recursion() {
        let n = 50_000u32;
        let mut nodes: Vec<BuildNode> = (0..n)
            .map(|i| BuildNode { bounds: unit_at(i as f32), kind: BuildKind::Leaf { first: i, count: 1 } })
            .collect();
        let mut top = 0u32;
        for i in 1..n {
            let bounds = nodes[top as usize].bounds.union(&nodes[i as usize].bounds);
            let count = nodes[top as usize].prims_under() + 1;
            nodes.push(BuildNode { bounds, kind: BuildKind::Interior { children: [top, i], count } });
            top = nodes.len() as u32 - 1;
        }
        let boxes: Vec<Aabb> = (0..n).map(|i| unit_at(i as f32)).collect();
        let tree = collapse_leaves(&BuildTree { nodes, prims: (0..n).collect(), root: top }, 4);
        validate_bvh(&tree.into_bvh(), &boxes).unwrap();
    }
}
