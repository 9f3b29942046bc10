//! Each node's children put in the order an occlusion ray should visit them: the children most
//! likely to stop the ray for the least work first. This is the traversal order of Ize and Hansen
//! (2011), "RTSAH Traversal Order for Occlusion Rays" (Computer Graphics Forum 30(2)), computed
//! once after the build and stored as the children's slot order, so that the any-hit walk needs
//! no per-ray sort.
//!
//! For a random line through a convex box `B`, the chance that it also meets a convex set `A`
//! inside it is `SA(A) / SA(B)` (Cauchy and Crofton); a flat triangle counts twice its area. So a
//! leaf stops a ray that enters its box with probability `1 - prod(1 - 2 area(t) / SA(leaf))` (the
//! triangles taken as independent), and costs its blocks' tests. A node costs its own test, then
//! each child in turn, reached if no child before it stopped the ray; it stops the ray if some
//! child does. Visiting first the children of greatest `p / c` (chance of stopping the ray over
//! the expected work) minimises the expected work of a walk that ends at its first occluder, the
//! rule for a sequence of independent trials.
//!
//! The order only steers the walk: every child the ray enters is still visited unless an occluder
//! was found, so answers do not depend on it.

use super::node::{EMPTY, WIDTH, WideNode, index_of, is_leaf};
use crate::Aabb;

/// Work of one node test, in the unit of [`order_for_occlusion`]'s leaf costs.
pub const NODE_COST: f32 = 1.0;

/// Puts the children of every node reachable from `root` in the order above; `leaf(first,
/// count, bounds)` gives a leaf child's chance of stopping a ray that enters `bounds` and the
/// work of testing it (in node tests). Returns the root's chance and work.
pub fn order_for_occlusion(
    nodes: &mut [WideNode],
    root: u32,
    leaf: &impl Fn(u32, u32, &Aabb) -> (f32, f32),
) -> (f32, f32) {
    let node = nodes[root as usize];
    let mut children: [(usize, f32, f32); WIDTH] = [(0, 0.0, 0.0); WIDTH];
    let mut used = 0;
    let mut bounds = Aabb::EMPTY;
    for slot in 0..WIDTH {
        let reference = node.children[slot];
        if reference == EMPTY {
            continue;
        }
        let b = node.child_bounds(slot);
        bounds = bounds.union(&b);
        let (p, c) = if is_leaf(reference) {
            leaf(index_of(reference), node.counts[slot] as u32, &b)
        } else {
            order_for_occlusion(nodes, reference, leaf)
        };
        children[used] = (slot, p, c);
        used += 1;
    }
    let children = &mut children[..used];
    children.sort_by(|a, b| (b.1 * a.2).total_cmp(&(a.1 * b.2)));
    let area = bounds.surface_area();
    let (mut missed, mut cost) = (1.0f32, NODE_COST);
    let mut weighted = node;
    for &(slot, p, c) in children.iter() {
        let enter = if area > 0.0 { (node.child_bounds(slot).surface_area() / area).min(1.0) } else { 1.0 };
        cost += missed * enter * c;
        missed *= 1.0 - enter * p;
        let w = p;
        weighted.weights[slot] = (w.to_bits() >> 16) as u16;
    }
    nodes[root as usize] = weighted;
    (1.0 - missed, cost)
}

/// The chance that a ray entering a box of surface area `box_area` meets a triangle of area
/// `area` inside it.
pub fn triangle_chance(area: f32, box_area: f32) -> f32 {
    if box_area > 0.0 { (2.0 * area / box_area).min(1.0) } else { 1.0 }
}

