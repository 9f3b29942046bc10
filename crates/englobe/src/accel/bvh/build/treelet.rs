//! Treelet restructuring: Karras and Aila (2013), "Fast Parallel Construction of High-Quality
//! Bounding Volume Hierarchies" (High Performance Graphics). A built tree is improved in place,
//! one small neighbourhood at a time, by the surface area heuristic (SAH).
//!
//! Children before parents, each interior node becomes the root of a *treelet*: starting from its
//! two children, the treelet's leaf with the largest box is replaced by its own two children until
//! the treelet has [`TREELET_LEAVES`] leaves (or no leaf left to open). The treelet's leaves are
//! subtrees, already optimised, with known costs; dynamic programming over every subset of them
//! finds the binary tree over them with the lowest SAH cost, and if it beats the present one the
//! treelet's interior nodes are rewired into it. The treelet's root keeps its place and its box,
//! so nothing above it changes. A subset's cost also considers collapsing it into one leaf (when it
//! holds at most `max_leaf` primitives), the choice [`super::collapse`] then makes.
//!
//! Costs use [`SAH_TRAVERSAL_COST`] and [`SAH_INTERSECTION_COST`], like every other SAH measure
//! here. Walks use explicit stacks, so degenerate (deep) trees are fine.

use crate::Aabb;
use crate::accel::bvh::layout::{BuildKind, BuildTree};
use crate::accel::bvh::stats::{SAH_INTERSECTION_COST, SAH_TRAVERSAL_COST};

/// Leaves of a treelet: 7, as Karras and Aila chose (the subsets to score grow as `3^n`).
pub const TREELET_LEAVES: usize = 7;
const SUBSETS: usize = 1 << TREELET_LEAVES;

/// Restructures `tree` in place with `passes` sweeps over all its interior nodes (see the module
/// documentation). Primitive references and leaves are not changed; only interior nodes are
/// rewired.
pub fn restructure(tree: &mut BuildTree, max_leaf: usize, passes: u32) {
    if tree.nodes.is_empty() {
        return;
    }
    let root_area = tree.nodes[tree.root as usize].bounds.surface_area() as f64;
    let weight = move |b: &Aabb| if root_area > 0.0 { b.surface_area() as f64 } else { 1.0 };
    let mut state = State { cost: vec![0.0; tree.nodes.len()], max_leaf: max_leaf.max(1), weight, subsets: None };
    let mut order = Vec::with_capacity(tree.nodes.len());
    let mut stack = Vec::new();
    for _ in 0..passes {
        // Parents before children; walked backwards, children before parents.
        order.clear();
        stack.push(tree.root);
        while let Some(id) = stack.pop() {
            order.push(id);
            if let BuildKind::Interior { children, .. } = tree.nodes[id as usize].kind {
                stack.extend(children);
            }
        }
        for &id in order.iter().rev() {
            state.visit(tree, id);
        }
    }
}

/// What the pass knows about the nodes already visited.
struct State<W> {
    /// SAH cost of each node's subtree, unnormalised (areas, not probabilities).
    cost: Vec<f64>,
    max_leaf: usize,
    weight: W,
    /// The dynamic programme's tables, kept from treelet to treelet (taken while in use).
    subsets: Option<Box<Subsets>>,
}

/// For each subset of a treelet's leaves: its box, primitives, best cost, and the part holding its
/// lowest leaf in its best split.
struct Subsets {
    boxes: [Aabb; SUBSETS],
    counts: [u32; SUBSETS],
    best: [f64; SUBSETS],
    part: [u8; SUBSETS],
}

impl Subsets {
    fn new() -> Box<Self> {
        Box::new(Subsets {
            boxes: [Aabb::EMPTY; SUBSETS],
            counts: [0; SUBSETS],
            best: [0.0; SUBSETS],
            part: [0; SUBSETS],
        })
    }
}

impl<W: Fn(&Aabb) -> f64> State<W> {
    /// The cost of a node over `count` primitives with box weight `w` whose children cost
    /// `children` together: an interior node, or a leaf if that is cheaper and allowed.
    fn node_cost(&self, w: f64, count: u32, children: f64) -> f64 {
        let split = SAH_TRAVERSAL_COST as f64 * w + children;
        if count as usize <= self.max_leaf { split.min(SAH_INTERSECTION_COST as f64 * w * count as f64) } else { split }
    }

    /// Visits node `id`, whose children have been visited: restructures its treelet and records
    /// its cost.
    fn visit(&mut self, tree: &mut BuildTree, id: u32) {
        let node = tree.nodes[id as usize];
        let w = (self.weight)(&node.bounds);
        let [a, b] = match node.kind {
            BuildKind::Leaf { count, .. } => {
                self.cost[id as usize] = SAH_INTERSECTION_COST as f64 * w * count as f64;
                return;
            }
            BuildKind::Interior { children, .. } => children,
        };
        let count = node.prims_under();
        let current = self.node_cost(w, count, self.cost[a as usize] + self.cost[b as usize]);
        self.cost[id as usize] = current;

        // Grow the treelet: open the largest leaf that is an interior node.
        let mut leaves = [0u32; TREELET_LEAVES];
        let mut interior = [0u32; TREELET_LEAVES - 1];
        (leaves[0], leaves[1], interior[0]) = (a, b, id);
        let (mut n, mut m) = (2usize, 1usize);
        while n < TREELET_LEAVES {
            let open = (0..n)
                .filter(|&i| matches!(tree.nodes[leaves[i] as usize].kind, BuildKind::Interior { .. }))
                .max_by(|&i, &j| {
                    let (x, y) = (tree.nodes[leaves[i] as usize].bounds, tree.nodes[leaves[j] as usize].bounds);
                    // Ties go to the first, for a deterministic treelet.
                    x.surface_area().total_cmp(&y.surface_area()).then(j.cmp(&i))
                });
            let Some(i) = open else { break };
            let BuildKind::Interior { children: [c, d], .. } = tree.nodes[leaves[i] as usize].kind else { break };
            interior[m] = leaves[i];
            m += 1;
            (leaves[i], leaves[n]) = (c, d);
            n += 1;
        }
        if n <= 2 {
            return;
        }

        // Best tree over every subset of the treelet's leaves; subsets come after their parts.
        let full = (1usize << n) - 1;
        let mut tables = self.subsets.take().unwrap_or_else(Subsets::new);
        let Subsets { boxes, counts, best, part } = &mut *tables;
        for s in 1..=full {
            let low = s & s.wrapping_neg();
            if s == low {
                let leaf = leaves[low.trailing_zeros() as usize] as usize;
                (boxes[s], counts[s], best[s]) =
                    (tree.nodes[leaf].bounds, tree.nodes[leaf].prims_under(), self.cost[leaf]);
                continue;
            }
            boxes[s] = boxes[low].union(&boxes[s ^ low]);
            counts[s] = counts[low] + counts[s ^ low];
            // Every split of `s` in two, each once: the part holding the lowest leaf, enumerated
            // as the submasks of the rest.
            let rest = s ^ low;
            let (mut cheapest, mut split) = (f64::INFINITY, 0usize);
            let mut q = rest;
            loop {
                let p = q | low;
                if p != s {
                    let c = best[p] + best[s ^ p];
                    if c < cheapest {
                        (cheapest, split) = (c, p);
                    }
                }
                if q == 0 {
                    break;
                }
                q = (q - 1) & rest;
            }
            best[s] = self.node_cost((self.weight)(&boxes[s]), counts[s], cheapest);
            part[s] = split as u8;
        }
        // Rewire only for a real gain, so rounding never churns a tree that is already optimal.
        if best[full] < current * (1.0 - 1e-9) {
            self.rewire(tree, id, &leaves, &interior, full, &tables);
        }
        self.subsets = Some(tables);
    }

    /// Rewires the treelet of `id` (its `leaves` and `interior` nodes) into the best tree over
    /// the subset `full` of its leaves, as `tables` describe it.
    fn rewire(
        &mut self,
        tree: &mut BuildTree,
        id: u32,
        leaves: &[u32; TREELET_LEAVES],
        interior: &[u32; TREELET_LEAVES - 1],
        full: usize,
        tables: &Subsets,
    ) {
        let mut free = 1usize;
        let mut todo = [(0usize, 0u32); TREELET_LEAVES];
        let mut len = 1usize;
        todo[0] = (full, id);
        while len > 0 {
            len -= 1;
            let (s, node) = todo[len];
            let mut child = |subset: usize| {
                if subset.is_power_of_two() {
                    leaves[subset.trailing_zeros() as usize]
                } else {
                    let c = interior[free];
                    free += 1;
                    todo[len] = (subset, c);
                    len += 1;
                    c
                }
            };
            let part = tables.part[s] as usize;
            let children = [child(part), child(s ^ part)];
            let n = &mut tree.nodes[node as usize];
            (n.bounds, n.kind) = (tables.boxes[s], BuildKind::Interior { children, count: tables.counts[s] });
            self.cost[node as usize] = tables.best[s];
        }
    }
}

#[cfg(test)]
mod tests {
    use glam::Vec3;
    use rand::{RngExt, SeedableRng};
    use rand_pcg::Pcg32;

    use super::*;
    use crate::accel::SeedPairing;
    use crate::accel::bvh::layout::BuildNode;
    use crate::accel::bvh::validate::validate_bvh;

    fn cube(c: Vec3, r: f32) -> Aabb {
        Aabb::new(c - Vec3::splat(r), c + Vec3::splat(r))
    }

    fn cloud(n: usize) -> Vec<Aabb> {
        let mut rng = Pcg32::seed_from_u64(0x2545_f491);
        let mut next = move || rng.random::<f32>();
        (0..n).map(|_| cube(Vec3::new(next(), next(), next()) * 50.0, 0.2 + next() * 2.0)).collect()
    }

    #[test]
    fn a_bad_tree_gets_better_and_stays_valid() {
        let boxes = cloud(5000);
        let mut tree = SeedPairing::build_tree(&boxes);
        let before = tree.clone().into_bvh().sah_cost();
        restructure(&mut tree, 1, 2);
        let bvh = tree.into_bvh();
        let q = validate_bvh(&bvh, &boxes).unwrap();
        assert!(q.tight && q.max_leaf == 1, "{q:?}");
        assert!(q.sah_cost < before * 0.5, "{} -> {}", before, q.sah_cost);
    }

    #[test]
    fn an_optimal_small_tree_is_left_alone() {
        // Four boxes on a line, paired as they should be: nothing to gain.
        let boxes: Vec<Aabb> = (0..4).map(|i| cube(Vec3::new(10.0 * i as f32, 0.0, 0.0), 1.0)).collect();
        let mut tree = SeedPairing::build_tree(&boxes);
        let before = tree.clone();
        restructure(&mut tree, 1, 3);
        assert_eq!(tree, before);
    }

    #[test]
    fn a_misgrouped_quad_is_regrouped() {
        // ((0, 2), (1, 3)) with 0, 1 close together and 2, 3 close together: becomes ((0, 1), (2, 3)).
        let boxes = [
            cube(Vec3::ZERO, 1.0),
            cube(Vec3::new(2.0, 0.0, 0.0), 1.0),
            cube(Vec3::new(50.0, 0.0, 0.0), 1.0),
            cube(Vec3::new(52.0, 0.0, 0.0), 1.0),
        ];
        let leaf = |i: u32| BuildNode { bounds: boxes[i as usize], kind: BuildKind::Leaf { first: i, count: 1 } };
        let join = |a: &BuildNode, b: &BuildNode, ca: u32, cb: u32| BuildNode {
            bounds: a.bounds.union(&b.bounds),
            kind: BuildKind::Interior { children: [ca, cb], count: a.prims_under() + b.prims_under() },
        };
        let (l0, l1, l2, l3) = (leaf(0), leaf(1), leaf(2), leaf(3));
        let n4 = join(&l0, &l2, 0, 2);
        let n5 = join(&l1, &l3, 1, 3);
        let n6 = join(&n4, &n5, 4, 5);
        let mut tree = BuildTree { nodes: vec![l0, l1, l2, l3, n4, n5, n6], prims: vec![0, 1, 2, 3], root: 6 };
        restructure(&mut tree, 1, 1);
        let bvh = tree.into_bvh();
        validate_bvh(&bvh, &boxes).unwrap();
        let n = bvh.nodes();
        assert_eq!(n[1].bounds(), boxes[0].union(&boxes[1]));
    }

    #[test]
    fn a_deep_chain_is_fine() {
        // A chain 30 000 deep, each level adding one box: walks without recursion.
        let n = 30_000u32;
        let boxes: Vec<Aabb> = (0..n).map(|i| cube(Vec3::new(i as f32, 0.0, 0.0), 0.4)).collect();
        let mut nodes: Vec<BuildNode> = (0..n)
            .map(|i| BuildNode { bounds: boxes[i as usize], kind: BuildKind::Leaf { first: i, count: 1 } })
            .collect();
        let mut top = 0u32;
        for i in 1..n {
            let bounds = nodes[top as usize].bounds.union(&nodes[i as usize].bounds);
            let count = nodes[top as usize].prims_under() + 1;
            nodes.push(BuildNode { bounds, kind: BuildKind::Interior { children: [top, i], count } });
            top = nodes.len() as u32 - 1;
        }
        let mut tree = BuildTree { nodes, prims: (0..n).collect(), root: top };
        restructure(&mut tree, 4, 1);
        validate_bvh(&tree.into_bvh(), &boxes).unwrap();
    }
}
