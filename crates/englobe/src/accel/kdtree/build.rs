//! The O(N log N) SAH kd-tree builder of Wald and Havran (2006), "On building fast kd-trees for
//! ray tracing, and on doing that in O(N log N)" (IEEE Symposium on Interactive Ray Tracing),
//! sections 4 and 5.
//!
//! The events of every primitive (see [`super::events`]) are sorted once. A node then finds its
//! best plane in one sweep over its sorted events, counting for each axis the primitives below,
//! above and lying in the candidate plane, and evaluating the surface area heuristic (SAH) of
//! Goldsmith and Salmon (1987) and MacDonald and Booth (1990) at every event, with the planar
//! primitives put on either side, whichever is cheaper. Splitting classifies the primitives into
//! below only, above only, and straddling; the events of the first two keep their order when
//! they are filtered into the children's lists, so only the straddling primitives need new events:
//! they are clipped to each child's cell (split clipping), their few events sorted, and merged into
//! the children's lists in linear time. Each level of the tree thus costs O(N), and the build
//! O(N log N).
//!
//! Termination: a node becomes a leaf when no plane's cost beats testing its primitives
//! (`intersection_cost * N`), when it holds [`KdTreeParams::leaf_size`] primitives or fewer, when it
//! reaches the depth limit, or when its cell has no area. Planes on the cell's boundary are not
//! candidates: they would cut off an empty slab of no volume, forever.

use super::events::{Event, EventKind, merge_events, prims_of, push_events, sort_events};
use super::{KdNode, KdTree, KdTreeParams, MAX_NODES};
use crate::Aabb;
use crate::accel::ClipFn;

/// Leaf lists stop growing past this many entries (indices are 32-bit); nodes that would need
/// more become leaves.
const MAX_LEAF_LIST_ENTRIES: usize = (u32::MAX / 2) as usize;

/// Where a primitive goes when its node is split.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Side {
    Both,
    Below,
    Above,
}

/// The cheapest plane of a node.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SplitPlane {
    /// Axis, 0 to 2.
    pub axis: usize,
    /// Position along the axis, strictly inside the cell.
    pub pos: f32,
    /// Whether the primitives lying in the plane go below it (otherwise above).
    pub planar_below: bool,
    /// SAH cost of the split.
    pub cost: f64,
}

/// The SAH cost of splitting `cell` at `pos` along `axis` with `below` and `above` primitives on
/// each side (`inv_area` is one over the cell's surface area).
#[inline]
pub fn split_cost(
    cell: &Aabb,
    axis: usize,
    pos: f32,
    below: usize,
    above: usize,
    params: &KdTreeParams,
    inv_area: f64,
) -> f64 {
    let e = cell.extent().as_dvec3();
    let (a, b) = (e[(axis + 1) % 3], e[(axis + 2) % 3]);
    let (lo, hi) = (cell.min[axis] as f64, cell.max[axis] as f64);
    let face = a * b;
    let around = a + b;
    let area_below = 2.0 * (face + (pos as f64 - lo) * around);
    let area_above = 2.0 * (face + (hi - pos as f64) * around);
    let bonus = if below == 0 || above == 0 { 1.0 - params.empty_bonus as f64 } else { 1.0 };
    bonus
        * (params.traversal_cost as f64
            + params.intersection_cost as f64 * inv_area * (area_below * below as f64 + area_above * above as f64))
}

/// The cheapest plane for a node of `n` primitives whose sorted events are `events`, in one sweep
/// (Wald and Havran's `FindPlane`); `None` if the cell has no area or no plane inside it.
pub fn find_plane(events: &[Event], n: usize, cell: &Aabb, params: &KdTreeParams) -> Option<SplitPlane> {
    let area = cell.surface_area() as f64;
    if !(area > 0.0) {
        return None;
    }
    let inv_area = 1.0 / area;
    let (mut below, mut planar, mut above) = ([0usize; 3], [0usize; 3], [n; 3]);
    let mut best: Option<SplitPlane> = None;
    let mut i = 0;
    while i < events.len() {
        let (axis, pos) = (events[i].axis as usize, events[i].pos);
        let mut count = [0usize; 3];
        for kind in [EventKind::End, EventKind::Planar, EventKind::Start] {
            while i < events.len() && events[i].axis as usize == axis && events[i].pos == pos && events[i].kind == kind
            {
                count[kind as usize] += 1;
                i += 1;
            }
        }
        let [ending, lying, starting] = count;
        planar[axis] = lying;
        above[axis] -= lying + ending;
        if pos > cell.min[axis] && pos < cell.max[axis] {
            let (b, p, a) = (below[axis], planar[axis], above[axis]);
            let with_below = split_cost(cell, axis, pos, b + p, a, params, inv_area);
            // With nothing in the plane, both sides cost the same.
            let with_above = if p == 0 { with_below } else { split_cost(cell, axis, pos, b, a + p, params, inv_area) };
            let (cost, planar_below) = if with_below <= with_above { (with_below, true) } else { (with_above, false) };
            if best.is_none_or(|s| cost < s.cost) {
                best = Some(SplitPlane { axis, pos, planar_below, cost });
            }
        }
        below[axis] += starting + lying;
        planar[axis] = 0;
    }
    best
}

pub(super) fn build(boxes: &[Aabb], clip: ClipFn<'_>, params: KdTreeParams) -> KdTree {
    let mut events = Vec::with_capacity(boxes.len() * 6);
    let mut bounds = Aabb::EMPTY;
    let mut n = 0;
    for (prim, b) in boxes.iter().enumerate() {
        if b.is_empty() || !b.is_finite() {
            continue;
        }
        push_events(&mut events, prim as u32, b);
        bounds = bounds.union(b);
        n += 1;
    }
    sort_events(&mut events);
    let mut builder = Builder {
        clip,
        params,
        max_depth: params.depth_limit(n),
        nodes: Vec::new(),
        leaf_lists: vec![0],
        side: vec![Side::Both; boxes.len()],
        depth: 0,
    };
    if n > 0 {
        builder.node(events, n, bounds, 0);
    }
    KdTree {
        nodes: builder.nodes,
        leaf_lists: builder.leaf_lists,
        bounds,
        depth: builder.depth,
        prim_count: boxes.len(),
        mailbox: params.mailbox,
    }
}

struct Builder<'a> {
    clip: ClipFn<'a>,
    params: KdTreeParams,
    max_depth: u32,
    nodes: Vec<KdNode>,
    leaf_lists: Vec<u32>,
    /// Per primitive, its side in the split being made (only the node's primitives are current).
    side: Vec<Side>,
    depth: u32,
}

impl Builder<'_> {
    /// Builds the subtree of a node of `n` primitives with sorted `events` and cell `cell`, laid
    /// out from the next free node on.
    fn node(&mut self, events: Vec<Event>, n: usize, cell: Aabb, depth: u32) {
        self.depth = self.depth.max(depth);
        let here = self.nodes.len();
        let may_split = n > self.params.leaf_size as usize
            && depth < self.max_depth
            && here + 2 < MAX_NODES
            && self.leaf_lists.len() + 2 * events.len() < MAX_LEAF_LIST_ENTRIES;
        let leaf_cost = self.params.intersection_cost as f64 * n as f64;
        let plane = if may_split { find_plane(&events, n, &cell, &self.params) } else { None };
        let Some(plane) = plane.filter(|p| p.cost < leaf_cost) else {
            self.leaf(&events);
            return;
        };
        // The child above is not laid out yet: patched below.
        self.nodes.push(KdNode::leaf(0));
        let (below_cell, above_cell) = KdTree::split_cell(&cell, plane.axis, plane.pos);
        let ((below, n_below), (above, n_above)) = self.split(events, &below_cell, &above_cell, &plane);
        self.node(below, n_below, below_cell, depth + 1);
        let above_index = self.nodes.len() as u32;
        self.nodes[here] = KdNode::interior(plane.axis, plane.pos, above_index);
        self.node(above, n_above, above_cell, depth + 1);
    }

    /// A leaf over the primitives of `events`.
    fn leaf(&mut self, events: &[Event]) {
        let mut prims: Vec<u32> = prims_of(events).collect();
        if prims.is_empty() {
            self.nodes.push(KdNode::leaf(0));
            return;
        }
        prims.sort_unstable();
        let offset = self.leaf_lists.len() as u32;
        self.leaf_lists.push(prims.len() as u32);
        self.leaf_lists.extend_from_slice(&prims);
        self.nodes.push(KdNode::leaf(offset));
    }

    /// Splits a node's events into its children's: classification, filtering, clipping of the
    /// straddling primitives and merging (Wald and Havran, section 4.4). Returns each child's
    /// sorted events and primitive count.
    fn split(
        &mut self,
        events: Vec<Event>,
        below_cell: &Aabb,
        above_cell: &Aabb,
        plane: &SplitPlane,
    ) -> ((Vec<Event>, usize), (Vec<Event>, usize)) {
        for prim in prims_of(&events) {
            self.side[prim as usize] = Side::Both;
        }
        let axis_events = {
            let start = events.partition_point(|e| (e.axis as usize) < plane.axis);
            let end = events.partition_point(|e| (e.axis as usize) <= plane.axis);
            &events[start..end]
        };
        for e in axis_events {
            let side = &mut self.side[e.prim as usize];
            match e.kind {
                EventKind::End if e.pos <= plane.pos => *side = Side::Below,
                EventKind::Start if e.pos >= plane.pos => *side = Side::Above,
                EventKind::Planar => {
                    let goes_below = e.pos < plane.pos || (e.pos == plane.pos && plane.planar_below);
                    *side = if goes_below { Side::Below } else { Side::Above };
                }
                _ => {}
            }
        }
        // Exact sizes first: the lists of a deep tree's pending siblings are what the build's
        // memory is made of.
        let (mut size_below, mut size_above) = (0, 0);
        for e in &events {
            match self.side[e.prim as usize] {
                Side::Below => size_below += 1,
                Side::Above => size_above += 1,
                Side::Both => {}
            }
        }
        let (mut below, mut above) = (Vec::with_capacity(size_below), Vec::with_capacity(size_above));
        let (mut n_below, mut n_above) = (0, 0);
        let mut straddling = Vec::new();
        for e in &events {
            let first_of_prim = e.axis == 0 && e.kind != EventKind::End;
            match self.side[e.prim as usize] {
                Side::Below => {
                    below.push(*e);
                    n_below += first_of_prim as usize;
                }
                Side::Above => {
                    above.push(*e);
                    n_above += first_of_prim as usize;
                }
                Side::Both if first_of_prim => straddling.push(e.prim),
                Side::Both => {}
            }
        }
        drop(events);
        let (mut new_below, mut new_above) = (Vec::new(), Vec::new());
        for prim in straddling {
            for (cell, out, count) in
                [(below_cell, &mut new_below, &mut n_below), (above_cell, &mut new_above, &mut n_above)]
            {
                // The clipper's answer is trusted only inside the cell, and only if it is a box.
                let part = (self.clip)(prim, cell).intersection(cell);
                if !part.is_empty() && part.is_finite() {
                    push_events(out, prim, &part);
                    *count += 1;
                }
            }
        }
        sort_events(&mut new_below);
        sort_events(&mut new_above);
        ((merge_events(below, new_below), n_below), (merge_events(above, new_above), n_above))
    }
}

#[cfg(test)]
mod tests {
    use glam::Vec3;
    use rand::{RngExt, SeedableRng};
    use rand_pcg::Pcg32;

    use super::*;

    fn params() -> KdTreeParams {
        KdTreeParams::default()
    }

    /// The cheapest plane by brute force: every event position of every axis, primitives counted
    /// one by one.
    fn naive_plane(boxes: &[Aabb], cell: &Aabb, params: &KdTreeParams) -> Option<f64> {
        let inv_area = 1.0 / cell.surface_area() as f64;
        let mut best: Option<f64> = None;
        for axis in 0..3 {
            for pos in boxes.iter().flat_map(|b| [b.min[axis], b.max[axis]]) {
                if !(pos > cell.min[axis] && pos < cell.max[axis]) {
                    continue;
                }
                let (mut below, mut above, mut planar) = (0, 0, 0);
                for b in boxes {
                    if b.min[axis] == pos && b.max[axis] == pos {
                        planar += 1;
                    } else {
                        below += (b.min[axis] < pos) as usize;
                        above += (b.max[axis] > pos) as usize;
                    }
                }
                for (nb, na) in [(below + planar, above), (below, above + planar)] {
                    let c = split_cost(cell, axis, pos, nb, na, params, inv_area);
                    best = Some(best.map_or(c, |b: f64| b.min(c)));
                }
            }
        }
        best
    }

    fn events_of(boxes: &[Aabb]) -> Vec<Event> {
        let mut e = Vec::new();
        for (i, b) in boxes.iter().enumerate() {
            push_events(&mut e, i as u32, b);
        }
        sort_events(&mut e);
        e
    }

    #[test]
    fn the_sweep_finds_the_cheapest_plane_brute_force_finds() {
        let mut rng = Pcg32::seed_from_u64(0x1234_5678);
        let mut next = move |n: u32| rng.random_range(0..n);
        for round in 0..200 {
            let n = 1 + next(40) as usize;
            // Integer coordinates on a small lattice: shared positions and flat boxes are common.
            let boxes: Vec<Aabb> = (0..n)
                .map(|_| {
                    let a = Vec3::new(next(9) as f32, next(9) as f32, next(9) as f32);
                    let b = Vec3::new(next(4) as f32, next(4) as f32, next(4) as f32);
                    // Some rounds have only flat boxes and points, some half-unit sizes.
                    Aabb::new(a, a + b * [1.0, 0.0, 0.5][round % 3])
                })
                .collect();
            let cell = boxes.iter().fold(Aabb::EMPTY, |c, b| c.union(b));
            if !(cell.surface_area() > 0.0) {
                continue;
            }
            let swept = find_plane(&events_of(&boxes), n, &cell, &params()).map(|p| p.cost);
            let naive = naive_plane(&boxes, &cell, &params());
            match (swept, naive) {
                (Some(s), Some(b)) => assert!((s - b).abs() <= 1e-9 * b, "round {round}: {s} vs {b}"),
                (s, b) => assert_eq!(s, b, "round {round}"),
            }
        }
    }

    #[test]
    fn empty_space_is_cut_off() {
        // Two clusters at either end of a long box: the best plane lies in the gap.
        let mut boxes = Vec::new();
        for i in 0..8 {
            let y = i as f32 * 0.1;
            boxes.push(Aabb::new(Vec3::new(0.0, y, 0.0), Vec3::new(1.0, y + 0.1, 1.0)));
            boxes.push(Aabb::new(Vec3::new(99.0, y, 0.0), Vec3::new(100.0, y + 0.1, 1.0)));
        }
        let cell = boxes.iter().fold(Aabb::EMPTY, |c, b| c.union(b));
        let p = find_plane(&events_of(&boxes), boxes.len(), &cell, &params()).unwrap();
        assert_eq!(p.axis, 0);
        assert!(p.pos == 1.0 || p.pos == 99.0, "{p:?}");
        let tree = KdTree::build(&boxes);
        assert!(tree.depth() >= 2 && tree.nodes().len() >= 5);
    }

    #[test]
    fn copies_of_one_box_stay_in_one_leaf() {
        let boxes = vec![Aabb::new(Vec3::ZERO, Vec3::ONE); 50];
        let tree = KdTree::build(&boxes);
        assert_eq!(tree.nodes().len(), 1);
        assert_eq!(tree.leaf_prims(&tree.nodes()[0]), (0..50).collect::<Vec<u32>>());
    }

    #[test]
    fn flat_primitives_in_the_split_plane_go_to_one_side() {
        // Squares lying in the plane x = 1, between boxes on either side.
        let mut boxes = vec![
            Aabb::new(Vec3::new(0.0, 0.0, 0.0), Vec3::new(0.5, 1.0, 1.0)),
            Aabb::new(Vec3::new(1.5, 0.0, 0.0), Vec3::new(2.0, 1.0, 1.0)),
        ];
        boxes.extend((0..4).map(|_| Aabb::new(Vec3::new(1.0, 0.0, 0.0), Vec3::new(1.0, 1.0, 1.0))));
        let tree = KdTree::build(&boxes);
        let referenced: usize = tree.nodes().iter().filter(|n| n.is_leaf()).map(|n| tree.leaf_prims(n).len()).sum();
        assert_eq!(referenced, 6, "no primitive is referenced twice: {tree:?}");
    }

    #[test]
    fn the_depth_limit_and_the_leaf_size_hold() {
        let boxes: Vec<Aabb> =
            (0..1000).map(|i| Aabb::new(Vec3::new(i as f32, 0.0, 0.0), Vec3::new(i as f32 + 0.5, 1.0, 1.0))).collect();
        let shallow = KdTree::build_with_clipper(
            &boxes,
            &|p, c| boxes[p as usize].intersection(c),
            KdTreeParams { max_depth: Some(3), ..params() },
        );
        assert_eq!(shallow.depth(), 3);
        let coarse = KdTree::build_with_clipper(
            &boxes,
            &|p, c| boxes[p as usize].intersection(c),
            KdTreeParams { leaf_size: 100, ..params() },
        );
        assert!(coarse.nodes().iter().filter(|n| n.is_leaf()).all(|n| coarse.leaf_prims(n).len() <= 100));
        assert!(coarse.nodes().len() < KdTree::build(&boxes).nodes().len());
        assert!(KdTree::build(&boxes).depth() <= KdTreeParams::default().depth_limit(1000));
    }

    #[test]
    fn a_clipper_that_drops_a_primitive_from_a_side_is_obeyed() {
        // A diagonal "triangle" spanning the whole cell, which its clipper says lies only where
        // x + y <= 4; a cluster of boxes in the far corner makes the tree split there.
        let mut boxes = vec![Aabb::new(Vec3::ZERO, Vec3::new(4.0, 4.0, 1.0))];
        boxes.extend((0..20).map(|i| {
            let o = Vec3::new(3.5 + (i % 5) as f32 * 0.1, 3.5 + (i / 5) as f32 * 0.1, 0.0);
            Aabb::new(o, o + Vec3::new(0.05, 0.05, 1.0))
        }));
        let clip = |p: u32, c: &Aabb| {
            if p == 0 && c.min.x + c.min.y > 4.0 { Aabb::EMPTY } else { boxes[p as usize].intersection(c) }
        };
        let tree = KdTree::build_with_clipper(&boxes, &clip, params());
        let with_big: usize = tree.nodes().iter().filter(|n| n.is_leaf() && tree.leaf_prims(n).contains(&0)).count();
        let leaves = tree.nodes().iter().filter(|n| n.is_leaf()).count();
        assert!(with_big < leaves, "the big primitive is left out of the far corner's leaves");
    }

    #[test]
    fn nothing_to_build() {
        let tree = KdTree::build(&[]);
        assert!(tree.nodes().is_empty() && tree.bounds().is_empty());
        let tree = KdTree::build(&[Aabb::EMPTY, Aabb::new(Vec3::splat(f32::NAN), Vec3::ONE)]);
        assert!(tree.nodes().is_empty());
        let point = Aabb::new(Vec3::ONE, Vec3::ONE);
        let tree = KdTree::build(&[point; 10]);
        assert_eq!(tree.nodes().len(), 1, "a cell of no area is a leaf");
    }
}
