//! The invariants of the two wide structures, checked by one walk: every node reached exactly once
//! from the root, every child box inside its parent's, no empty leaf, leaf ranges in bounds, the
//! recorded depth the real one; then per leaf, every primitive inside its leaf's box and listed
//! once. [`WideBvh`] must list every primitive; [`TriangleBvh`] every triangle it says it stored
//! (it leaves out the zero-area ones, which are never hit), each in a block lane whose vertices
//! have the triangle's box, in leaves that together cover the triangle (a triangle cut before
//! the build lies in several).

use super::node::{EMPTY, WIDTH, WideNode, index_of, is_leaf};
use super::triangles::UNUSED;
use super::{TriangleBvh, WideBvh};
use crate::Aabb;
use crate::accel::{Accel, ClipFn, InvalidStructure, StructureStats, Validate};
use crate::shapes::clip_triangle;

/// A broken invariant of a wide BVH.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
#[error("{0}")]
pub struct WideBvhError(pub String);

/// Walks the nodes from the root; `leaf(box, first, count, seen)` checks one leaf and marks the
/// primitives it holds in `seen`.
fn walk(
    nodes: &[WideNode],
    bounds: Aabb,
    depth: u32,
    prims: usize,
    mut leaf: impl FnMut(&Aabb, usize, usize, &mut [u32]) -> Result<(), String>,
) -> Result<Vec<u32>, String> {
    let mut seen = vec![0u32; prims];
    let mut reached = vec![false; nodes.len()];
    let mut real_depth = 0;
    let mut stack = if nodes.is_empty() { vec![] } else { vec![(0u32, bounds, 1u32)] };
    while let Some((i, parent, level)) = stack.pop() {
        let node = nodes.get(i as usize).ok_or(format!("child {i} is not a node"))?;
        if std::mem::replace(&mut reached[i as usize], true) {
            return Err(format!("node {i} is reached twice"));
        }
        real_depth = real_depth.max(level);
        for slot in (0..WIDTH).filter(|&s| node.children[s] != EMPTY) {
            let b = node.child_bounds(slot);
            if !parent.contains_box(&b) {
                return Err(format!("node {i}, slot {slot}: {b:?} is not inside {parent:?}"));
            }
            let c = node.children[slot];
            if !is_leaf(c) {
                stack.push((c, b, level + 1));
                continue;
            }
            if node.counts[slot] == 0 {
                return Err(format!("node {i}, slot {slot}: empty leaf"));
            }
            leaf(&b, index_of(c) as usize, node.counts[slot] as usize, &mut seen)
                .map_err(|e| format!("node {i}, slot {slot}: {e}"))?;
        }
    }
    if let Some(n) = reached.iter().position(|&r| !r) {
        return Err(format!("node {n} is not reachable"));
    }
    if real_depth != depth {
        return Err(format!("recorded depth {depth}, real depth {real_depth}"));
    }
    Ok(seen)
}

/// Marks `prim` seen in a leaf of box `leaf`, checking that it exists and lies inside.
fn mark(prim: u32, leaf: &Aabb, prim_boxes: &[Aabb], seen: &mut [u32]) -> Result<(), String> {
    let pb = prim_boxes.get(prim as usize).ok_or(format!("primitive {prim} does not exist"))?;
    if !leaf.contains_box(pb) {
        return Err(format!("primitive {prim} sticks out of its leaf"));
    }
    seen[prim as usize] += 1;
    Ok(())
}

impl Validate for WideBvh {
    fn validate(&self, prim_boxes: &[Aabb], _clip: Option<ClipFn<'_>>) -> Result<StructureStats, InvalidStructure> {
        let refs = self.prim_indices();
        let seen = walk(self.nodes(), self.bounds(), self.depth(), prim_boxes.len(), |b, first, count, seen| {
            let prims = refs.get(first..first + count).ok_or("bad leaf range")?;
            prims.iter().try_for_each(|&p| mark(p, b, prim_boxes, seen))
        })
        .and_then(|seen| match seen.iter().position(|&s| s != 1) {
            Some(p) => Err(format!("primitive {p} is in {} leaves", seen[p])),
            None => Ok(()),
        });
        seen.map_err(|e| InvalidStructure::new("wide BVH", WideBvhError(e)))?;
        Ok(self.stats())
    }
}

impl Validate for TriangleBvh {
    /// `prim_boxes[i]` is the box of triangle `i`. A triangle cut before the build (see
    /// [`super::presplit`]) may lie in several leaves, each holding part of it: each such leaf
    /// must meet the triangle, and the parts of the triangle inside its leaves must together
    /// cover the whole triangle's box.
    fn validate(&self, prim_boxes: &[Aabb], _clip: Option<ClipFn<'_>>) -> Result<StructureStats, InvalidStructure> {
        let (blocks, stats) = (self.blocks(), self.stats());
        let mut covered = vec![Aabb::EMPTY; prim_boxes.len()];
        let mut refs = 0;
        let checked = walk(self.nodes(), self.bounds(), self.depth(), prim_boxes.len(), |b, first, count, seen| {
            let mut in_leaf = Vec::new();
            for block in blocks.get(first..first + count).ok_or("bad leaf range")? {
                if block.used() == 0 {
                    return Err("a block with no triangle".to_owned());
                }
                for lane in 0..block.used() as usize {
                    let id = block.ids[lane];
                    if id == UNUSED {
                        return Err(format!("lane {lane} is unused but counted"));
                    }
                    let own = prim_boxes.get(id as usize).ok_or(format!("triangle {id} does not exist"))?;
                    if Aabb::from_points(block.vertices(lane)) != *own {
                        return Err(format!("triangle {id} is stored with other vertices"));
                    }
                    let part = clip_triangle(block.vertices(lane), b);
                    if part.is_empty() {
                        return Err(format!("triangle {id} does not meet its leaf"));
                    }
                    covered[id as usize] = covered[id as usize].union(&part);
                    seen[id as usize] += 1;
                    in_leaf.push(id);
                    refs += 1;
                }
            }
            in_leaf.sort_unstable();
            match in_leaf.windows(2).find(|w| w[0] == w[1]) {
                Some(w) => Err(format!("triangle {} is twice in one leaf", w[0])),
                None => Ok(()),
            }
        })
        .and_then(|seen| {
            if let Some(p) = (0..seen.len()).find(|&p| seen[p] > 0 && !covered[p].contains_box(&prim_boxes[p])) {
                return Err(format!("the leaves holding triangle {p} do not cover it"));
            }
            let stored = seen.iter().filter(|&&s| s > 0).count();
            if stored != self.stored {
                return Err(format!("{stored} triangles in the leaves, {} recorded", self.stored));
            }
            match refs == stats.prim_refs {
                true => Ok(()),
                false => Err(format!("{refs} references in the leaves, {} counted", stats.prim_refs)),
            }
        });
        checked.map_err(|e| InvalidStructure::new("triangle BVH", WideBvhError(e)))?;
        Ok(stats)
    }
}
