//! The agglomerative builder: Parallel Locally-Ordered Clustering (PLOC), Meister and Bittner
//! (2018), "Parallel Locally-Ordered Clustering for Bounding Volume Hierarchy Construction" (IEEE
//! Transactions on Visualization and Computer Graphics). It is the seed report's bottom-up idea,
//! "pair the nearest boxes", with a real nearest-neighbour search.
//!
//! 1. Every primitive starts as a cluster of its own; clusters are sorted by the Morton code of
//!    their centroid ([`super::morton`]), so that clusters near in space are near in the list.
//! 2. Each cluster finds its nearest neighbour among the [`Ploc::radius`] clusters on either side
//!    of it in the list, "nearest" meaning the smallest surface area of the box around both.
//! 3. Clusters that are each other's nearest neighbour merge: the pair becomes one cluster at the
//!    place of its first member; the list is compacted, and steps 2 and 3 repeat until one
//!    cluster, the root, remains.
//!
//! Step 2 runs in parallel over the clusters. Ties in step 2 are broken by a total order on pairs
//! (the area, then how far apart the two are in the list, then the parity and position of the
//! first), the same for every cluster: the smallest pair of the whole list is therefore always
//! mutual, so every round merges at least once, and copies of one box pair up with their
//! neighbours instead of all choosing the same one.
//!
//! One safeguard goes beyond the paper: on inputs such as boxes nested inside one another, every
//! cluster's nearest neighbour is the next smaller box, and only one pair per round is mutual,
//! which would make the build quadratic. When fewer than one cluster in [`STALL_FRACTION`] merges
//! in a round, the round also merges each remaining cluster with its nearest neighbour if that one
//! is still free, in list order; a neighbour is within the radius, so at least one cluster in
//! `2 * radius + 2` merges, and the number of rounds stays logarithmic.
//!
//! Greedy merging makes good low levels but weaker high ones: on scanned meshes (the Stanford
//! bunny) the clustered tree's SAH cost is about 10 % above the full-sweep builder's (11 % with a
//! radius of 16). Two sweeps of treelet restructuring ([`super::treelet`], Karras and Aila 2013)
//! bring it to 7 % (see `docs/bvh.md`); [`Ploc::restructure_passes`] set to 0 gives PLOC alone. PLOC makes one
//! primitive per leaf; a final pass ([`super::collapse`]) collapses the subtrees that the SAH says
//! cost less as a leaf, so that its trees compare with the top-down builders'.

use super::binned_sah::DEFAULT_MAX_LEAF;
use super::collapse::collapse_leaves;
use super::morton::MortonGrid;
use super::parallel;
use super::treelet::restructure;
use crate::Aabb;
use crate::accel::bvh::Bvh;
use crate::accel::bvh::layout::{BuildKind, BuildNode, BuildTree};

/// Rounds in which fewer than one cluster in this many merges also merge greedily (see the
/// module documentation).
pub const STALL_FRACTION: usize = 16;

/// The PLOC builder. `Ploc::default()` searches 8 clusters on each side, restructures the tree
/// twice and collapses it into leaves of at most 8 primitives.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Ploc {
    /// Clusters searched on each side of a cluster in Morton order (at least 1). Larger finds
    /// nearer neighbours at a cost linear in it.
    pub radius: usize,
    /// Most primitives per leaf after collapsing (at least 1).
    pub max_leaf: usize,
    /// Sweeps of treelet restructuring ([`super::treelet`]) over the clustered tree before its
    /// leaves are collapsed; 0 for PLOC alone.
    pub restructure_passes: u32,
}

impl Default for Ploc {
    fn default() -> Self {
        Ploc { radius: 8, max_leaf: DEFAULT_MAX_LEAF, restructure_passes: 2 }
    }
}

/// No partner.
const NONE: u32 = u32::MAX;

/// The order in which a cluster prefers its candidates: by the area of the box around both, then
/// by a key of the pair `a < b` that every cluster computes alike (see the module documentation).
/// The area's bits order like the area itself (it is never negative); NaN counts as the largest.
#[inline(always)]
fn pair_key(area: f32, a: usize, b: usize) -> (u32, u32, u32, u32) {
    let bits = if area.is_nan() { u32::MAX } else { area.max(0.0).to_bits() };
    (bits, (b - a) as u32, (a & 1) as u32, a as u32)
}

impl Ploc {
    /// Builds the tree over the primitives' boxes (primitive `i` has box `boxes[i]`).
    pub fn build(&self, boxes: &[Aabb]) -> Bvh {
        self.build_tree(boxes).into_bvh()
    }

    /// The tree before layout, leaves collapsed.
    pub fn build_tree(&self, boxes: &[Aabb]) -> BuildTree {
        let mut tree = self.cluster(boxes);
        restructure(&mut tree, self.max_leaf, self.restructure_passes);
        collapse_leaves(&tree, self.max_leaf.max(1))
    }

    /// The clustering alone: one primitive per leaf, the leaves first in Morton order, each
    /// merged node after its children, the root last.
    pub fn cluster(&self, boxes: &[Aabb]) -> BuildTree {
        let n = boxes.len();
        if n == 0 {
            return BuildTree::default();
        }
        let centroid_bounds = boxes.iter().fold(Aabb::EMPTY, |c, b| c.grown(b.center()));
        let grid = MortonGrid::new(&centroid_bounds);
        let mut keyed = vec![(0u64, 0u32); n];
        parallel::fill_indexed(&mut keyed, 1 << 12, |i| (grid.code(boxes[i].center()), i as u32));
        // Codes tie (coincident centroids); the index makes every key unique, the order unique.
        parallel::sort_unstable_by_key(&mut keyed, |&k| k);
        let prims: Vec<u32> = keyed.iter().map(|&(_, i)| i).collect();
        drop(keyed);

        let mut nodes = Vec::with_capacity(2 * n - 1);
        nodes.extend(prims.iter().enumerate().map(|(s, &p)| BuildNode {
            bounds: boxes[p as usize],
            kind: BuildKind::Leaf { first: s as u32, count: 1 },
        }));
        // The clusters in list order: their node and their box (kept beside for a tight search).
        let mut clusters: Vec<u32> = (0..n as u32).collect();
        let mut cluster_boxes: Vec<Aabb> = nodes.iter().map(|n| n.bounds).collect();
        let radius = self.radius.max(1);
        let mut nearest = vec![0u32; n];
        let mut partner = vec![NONE; n];
        while clusters.len() > 1 {
            let m = clusters.len();
            let nearest = &mut nearest[..m];
            let b = &cluster_boxes;
            parallel::fill_indexed(nearest, 256, |i| {
                let (lo, hi) = (i.saturating_sub(radius), (i + radius).min(m - 1));
                let mut best = (u32::MAX, u32::MAX, u32::MAX, u32::MAX);
                let mut best_j = i;
                for j in (lo..=hi).filter(|&j| j != i) {
                    let key = pair_key(b[i].union(&b[j]).surface_area(), i.min(j), i.max(j));
                    if key < best {
                        (best, best_j) = (key, j);
                    }
                }
                best_j as u32
            });

            let partner = &mut partner[..m];
            partner.fill(NONE);
            let mut merges = 0usize;
            for i in 0..m {
                let j = nearest[i] as usize;
                if nearest[j] as usize == i && i < j {
                    (partner[i], partner[j]) = (j as u32, i as u32);
                    merges += 1;
                }
            }
            if merges * STALL_FRACTION < m {
                for i in 0..m {
                    let j = nearest[i] as usize;
                    if partner[i] == NONE && partner[j] == NONE && j != i {
                        (partner[i], partner[j]) = (j as u32, i as u32);
                    }
                }
            }

            // Merge each pair at the place of its first member; compact.
            let mut kept = 0usize;
            for i in 0..m {
                let j = partner[i];
                if j == NONE {
                    clusters[kept] = clusters[i];
                    cluster_boxes[kept] = cluster_boxes[i];
                    kept += 1;
                } else if (i as u32) < j {
                    let j = j as usize;
                    let bounds = cluster_boxes[i].union(&cluster_boxes[j]);
                    let children = [clusters[i], clusters[j]];
                    let count = children.iter().map(|&c| nodes[c as usize].prims_under()).sum();
                    nodes.push(BuildNode { bounds, kind: BuildKind::Interior { children, count } });
                    clusters[kept] = nodes.len() as u32 - 1;
                    cluster_boxes[kept] = bounds;
                    kept += 1;
                }
            }
            clusters.truncate(kept);
            cluster_boxes.truncate(kept);
        }
        BuildTree { nodes, prims, root: clusters[0] }
    }
}

#[cfg(test)]
mod tests {
    use glam::Vec3;

    use super::*;
    use crate::accel::bvh::validate::validate_bvh;

    fn cube(c: Vec3, r: f32) -> Aabb {
        Aabb::new(c - Vec3::splat(r), c + Vec3::splat(r))
    }

    #[test]
    fn nearest_boxes_pair_first() {
        // Two tight pairs far apart: each pair is merged before the pairs are joined.
        let boxes = [
            cube(Vec3::new(0.0, 0.0, 0.0), 0.1),
            cube(Vec3::new(50.0, 0.0, 0.0), 0.1),
            cube(Vec3::new(0.3, 0.0, 0.0), 0.1),
            cube(Vec3::new(50.3, 0.0, 0.0), 0.1),
        ];
        let tree = Ploc::default().cluster(&boxes);
        let bvh = tree.into_bvh();
        let q = validate_bvh(&bvh, &boxes).unwrap();
        assert_eq!((q.leaves, q.depth), (4, 2));
        let n = bvh.nodes();
        let first = n[1].bounds();
        assert!(first.max.x < 1.0 || first.min.x > 49.0, "{first:?} mixes the pairs");
    }

    #[test]
    fn copies_of_one_box_pair_with_their_neighbours() {
        // All pairs tie: the pair order makes half of the clusters merge every round, so the
        // tree is balanced.
        let boxes = vec![cube(Vec3::ZERO, 1.0); 1024];
        let bvh = Ploc { radius: 4, max_leaf: 1, restructure_passes: 0 }.build(&boxes);
        let q = validate_bvh(&bvh, &boxes).unwrap();
        assert_eq!(q.depth, 10);
    }

    #[test]
    fn nested_boxes_do_not_stall() {
        // Box i holds box i - 1: each cluster's nearest is its smaller neighbour, one pair per
        // round is mutual; the greedy rounds keep the depth logarithmic-ish and the build quick.
        let boxes: Vec<Aabb> = (0..20_000).map(|i| cube(Vec3::ZERO, 1.0 + i as f32)).collect();
        let bvh = Ploc { radius: 8, max_leaf: 1, restructure_passes: 0 }.build(&boxes);
        let q = validate_bvh(&bvh, &boxes).unwrap();
        assert!(q.depth < 200, "{q:?}");
    }

    #[test]
    fn leaves_are_collapsed_by_the_sah() {
        let boxes: Vec<Aabb> = (0..64).map(|i| cube(Vec3::new((i / 4) as f32 * 10.0, 0.0, 0.0), 1.0)).collect();
        let q = validate_bvh(&Ploc::default().build(&boxes), &boxes).unwrap();
        assert_eq!((q.leaves, q.min_leaf, q.max_leaf), (16, 4, 4), "{q:?}");
    }

    #[test]
    fn the_same_tree_every_time() {
        let boxes: Vec<Aabb> = (0..30_000)
            .map(|i| cube(Vec3::new((i * 7919 % 1000) as f32, (i % 97) as f32, (i % 13) as f32), 0.5))
            .collect();
        assert_eq!(Ploc::default().build(&boxes), Ploc::default().build(&boxes));
    }

    #[test]
    fn treelet_restructuring_never_worsens_the_clustered_tree() {
        use rand::{RngExt, SeedableRng};
        use rand_pcg::Pcg32;
        let mut rng = Pcg32::seed_from_u64(0x2545_f491);
        let mut next = move || rng.random::<f32>();
        let boxes: Vec<Aabb> = (0..3000)
            .map(|_| {
                let (c, r) = (glam::Vec3::new(next(), next(), next()) * 50.0, 0.2 + next() * 2.0);
                Aabb::new(c - glam::Vec3::splat(r), c + glam::Vec3::splat(r))
            })
            .collect();
        let mut tree = Ploc::default().cluster(&boxes);
        let before = tree.clone().into_bvh().sah_cost();
        super::super::treelet::restructure(&mut tree, 1, 2);
        let after = crate::accel::bvh::validate_bvh(&tree.into_bvh(), &boxes).unwrap().sah_cost;
        assert!(after <= before, "{before} -> {after}");
    }
}
