//! The full-sweep surface area heuristic (SAH) builder, the quality reference the faster builders
//! are measured against: MacDonald and Booth (1990), "Heuristics for Ray Tracing Using Space
//! Subdivision" (The Visual Computer), applied to BVHs as Wald, Boulos and Shirley (2007), "Ray
//! Tracing Deformable Scenes Using Dynamic Bounding Volume Hierarchies" (ACM Transactions on
//! Graphics) describe it.
//!
//! At each node the primitives are sorted by centroid along each axis in turn, and every one of
//! the `n - 1` ways to cut each sorted list in two is scored with the SAH: a sweep from the right
//! records the area of each suffix's box, a sweep from the left scores each cut. The cheapest cut
//! of the three axes wins if it costs less than a leaf (see [`super::top_down::split_beats_leaf`])
//! or if the node holds more than [`SweepSah::max_leaf`] primitives. Sorting at every node makes
//! the build `O(n log^2 n)`: slow next to binning, but it considers every candidate that a
//! partition by centroid order can produce. Large subtrees are built in parallel.

use std::cmp::Ordering;

use super::binned_sah::DEFAULT_MAX_LEAF;
use super::top_down::{self, PrimRef, Splitter, split_beats_leaf};
use crate::Aabb;
use crate::accel::bvh::{BuildTree, Bvh, SAH_TRAVERSAL_COST};

/// The full-sweep SAH builder. `SweepSah::default()` makes leaves of at most 8 primitives, like
/// [`super::BinnedSah::default()`], so that their trees compare.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct SweepSah {
    /// Most primitives per leaf (at least 1).
    pub max_leaf: usize,
}

impl Default for SweepSah {
    fn default() -> Self {
        SweepSah { max_leaf: DEFAULT_MAX_LEAF }
    }
}

impl SweepSah {
    /// Builds the tree over the primitives' boxes (primitive `i` has box `boxes[i]`).
    pub fn build(&self, boxes: &[Aabb]) -> Bvh {
        self.build_tree(boxes).into_bvh()
    }

    /// The tree before layout.
    pub fn build_tree(&self, boxes: &[Aabb]) -> BuildTree {
        top_down::build_tree(self, boxes)
    }
}

/// Sorts by centroid along `axis`, the index breaking ties, so the order is deterministic.
fn sort_along(refs: &mut [PrimRef], axis: usize) {
    refs.sort_unstable_by(|a, b| match a.centroid()[axis].total_cmp(&b.centroid()[axis]) {
        Ordering::Equal => a.index().cmp(&b.index()),
        other => other,
    });
}

impl Splitter for SweepSah {
    /// Area times count of every suffix of the sorted list.
    type Scratch = Vec<f32>;

    fn max_leaf(&self) -> usize {
        self.max_leaf
    }

    fn split(
        &self,
        refs: &mut [PrimRef],
        bounds: &Aabb,
        centroid_bounds: &Aabb,
        must_split: bool,
        right: &mut Vec<f32>,
    ) -> Option<usize> {
        let n = refs.len();
        let extent = centroid_bounds.extent();
        // (area-weighted count of both sides, axis, first of the second side)
        let mut best: Option<(f32, usize, usize)> = None;
        let mut sorted = None;
        // Along an axis where all centroids are equal, the sorted order is the index order, and
        // cutting it is a split by count: the driver's fallback does that without sorting.
        for axis in (0..3).filter(|&a| extent[a] > 0.0) {
            sort_along(refs, axis);
            sorted = Some(axis);
            right.clear();
            right.resize(n, 0.0);
            let mut suffix = Aabb::EMPTY;
            for i in (1..n).rev() {
                suffix = suffix.union(&refs[i].bounds());
                right[i] = suffix.surface_area() * (n - i) as f32;
            }
            let mut prefix = Aabb::EMPTY;
            for i in 1..n {
                prefix = prefix.union(&refs[i - 1].bounds());
                let cost = prefix.surface_area() * i as f32 + right[i];
                if best.is_none_or(|(c, _, _)| cost < c) {
                    best = Some((cost, axis, i));
                }
            }
        }
        let (weighted, axis, mid) = best?;
        if !must_split && !split_beats_leaf(weighted, bounds.surface_area(), n, SAH_TRAVERSAL_COST) {
            return None;
        }
        if sorted != Some(axis) {
            sort_along(refs, axis);
        }
        Some(mid)
    }
}

#[cfg(test)]
mod tests {
    use glam::Vec3;
    use rand::{RngExt, SeedableRng};
    use rand_pcg::Pcg32;

    use super::*;
    use crate::accel::bvh::BinnedSah;
    use crate::accel::bvh::validate::validate_bvh;

    fn cube(c: Vec3, r: f32) -> Aabb {
        Aabb::new(c - Vec3::splat(r), c + Vec3::splat(r))
    }

    /// A deterministic cloud of boxes of mixed sizes.
    fn cloud(n: usize) -> Vec<Aabb> {
        let mut rng = Pcg32::seed_from_u64(0x9e37_79b9);
        let mut next = move || rng.random::<f32>();
        (0..n).map(|_| cube(Vec3::new(next(), next(), next()) * 100.0, 0.1 + next() * next() * 5.0)).collect()
    }

    #[test]
    fn better_than_few_bins() {
        let boxes = cloud(3000);
        let (sweep, binned) = (
            SweepSah::default().build(&boxes),
            BinnedSah { bins: 4, max_leaf: 8, ..BinnedSah::default() }.build(&boxes),
        );
        assert!(sweep.sah_cost() < binned.sah_cost(), "{} vs {}", sweep.sah_cost(), binned.sah_cost());
    }

    #[test]
    fn never_worse_than_binning_on_a_cloud() {
        let boxes = cloud(3000);
        let sweep = SweepSah::default().build(&boxes);
        let q = validate_bvh(&sweep, &boxes).unwrap();
        assert!(q.tight && q.max_leaf <= DEFAULT_MAX_LEAF, "{q:?}");
        let binned = BinnedSah::default().build(&boxes);
        // Greedy top-down choices are not globally optimal, so allow a sliver.
        assert!(sweep.sah_cost() <= binned.sah_cost() * 1.01, "{} vs {}", sweep.sah_cost(), binned.sah_cost());
        // And binning with many bins comes close to it.
        assert!(binned.sah_cost() <= sweep.sah_cost() * 1.1, "{} vs {}", sweep.sah_cost(), binned.sah_cost());
    }

    #[test]
    fn the_same_tree_every_time() {
        let boxes = cloud(20_000);
        assert_eq!(SweepSah::default().build(&boxes), SweepSah::default().build(&boxes));
    }
}
