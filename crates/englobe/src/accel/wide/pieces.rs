//! Wide subtrees made apart, in parallel, and stored together once.
//!
//! The conversion ([`super::convert()`]) and the direct build ([`super::build`](mod@super::build))
//! make a large tree's top nodes first and their subtrees in parallel, each into nodes and leaf
//! items of its own. Appending each subtree to its parent's nodes as soon as it is done would copy
//! a node once for every parallel level above it (four, on a large tree; the root's copy on a
//! single core). Instead the pieces are kept apart, in storage order, each with node and item
//! references of its own, and copied once into the final array, in parallel, their references
//! moved as they go.
//!
//! While they wait for that copy, the pieces' nodes and items are kept in one [`Arena`] each for
//! the whole build (see [`super::arena`]).

use super::arena::{Arena, Stored};
use super::node::{EMPTY, LEAF, WideNode, index_of, is_leaf};
use super::output::{LeafSink, WideLayout};
use crate::accel::bvh::build::parallel::collect_indexed_huge;

/// Where the pieces of one build keep their nodes and leaf items until they are stored together.
pub(super) struct Store<K: LeafSink> {
    nodes: Arena<WideNode>,
    items: Arena<K::Item>,
}

impl<K: LeafSink> Store<K> {
    /// Room for the pieces of a build over `prims` primitives. A leaf has no more items than
    /// primitives; wide nodes number far fewer than the primitives (one per eleven or so
    /// triangles in a triangle BVH, whose leaves hold up to sixteen), and a piece that finds no
    /// room left keeps its own nodes.
    pub(super) fn for_prims(prims: usize) -> Self {
        Store { nodes: Arena::with_capacity(prims / 4 + 64), items: Arena::with_capacity(prims + 64) }
    }
}

/// A wide subtree as pieces, in the order they are stored: the first piece holds the subtree's
/// root.
pub(super) struct Pieces<K: LeafSink> {
    pieces: Vec<Piece<K>>,
    /// Wide nodes on the longest path from the subtree's root to a leaf.
    depth: u32,
}

/// Nodes and leaf items whose references count from the piece's own first node and item.
struct Piece<K: LeafSink> {
    nodes: Stored<WideNode>,
    items: Stored<K::Item>,
    /// Interior slots of the piece's first node whose subtree starts `delta` pieces further on.
    links: Vec<(usize, usize)>,
}

impl<K: LeafSink + Send + Sync> Pieces<K> {
    /// A subtree made in one walk (its root is node 0), its leaves in `items`, kept in `store`.
    pub(super) fn walked(layout: WideLayout, items: K, store: &Store<K>) -> Self {
        let piece = Piece {
            nodes: store.nodes.store(layout.nodes),
            items: store.items.store(items.into_items()),
            links: Vec::new(),
        };
        Pieces { pieces: vec![piece], depth: layout.depth }
    }

    /// The subtree of `node` (its leaves in `items`), whose interior children, slot by slot in
    /// increasing order, are `subtrees`.
    pub(super) fn joined(node: WideNode, items: K, subtrees: Vec<(usize, Pieces<K>)>) -> Self {
        let mut links = Vec::with_capacity(subtrees.len());
        let mut pieces = Vec::with_capacity(1 + subtrees.iter().map(|(_, s)| s.pieces.len()).sum::<usize>());
        pieces.push(Piece {
            nodes: Stored::Own(vec![node]),
            items: Stored::Own(items.into_items()),
            links: Vec::new(),
        });
        let mut depth = 1;
        for (slot, subtree) in subtrees {
            links.push((slot, pieces.len()));
            depth = depth.max(1 + subtree.depth);
            pieces.extend(subtree.pieces);
        }
        pieces[0].links = links;
        Pieces { pieces, depth }
    }

    /// The subtree's nodes (its root is node 0), every node copied once from where the pieces
    /// kept them (`store`, or their own), its leaf items appended to `sink`'s in order. The store
    /// is freed at the end.
    pub(super) fn assemble(self, store: Store<K>, sink: &mut K) -> WideLayout {
        // Where each piece's nodes and items start.
        let mut first_node = Vec::with_capacity(self.pieces.len());
        let mut first_item = Vec::with_capacity(self.pieces.len());
        let mut total = 0u32;
        let mut parts = Vec::with_capacity(self.pieces.len());
        for piece in self.pieces {
            first_node.push(total);
            total += store.nodes.get(&piece.nodes).len() as u32;
            first_item.push(sink.append(store.items.get(&piece.items)));
            parts.push((piece.nodes, piece.links));
        }
        let nodes = collect_indexed_huge(total as usize, 1 << 10, |i| {
            // The piece holding node `i`: the last one starting at or before it.
            let p = first_node.partition_point(|&f| f as usize <= i) - 1;
            let (nodes, links) = &parts[p];
            let local = i - first_node[p] as usize;
            let mut node = store.nodes.get(nodes)[local];
            for c in node.children.iter_mut().filter(|c| **c != EMPTY) {
                *c = if is_leaf(*c) { LEAF | (index_of(*c) + first_item[p]) } else { *c + first_node[p] };
            }
            if local == 0 {
                for &(slot, delta) in links {
                    node.children[slot] = first_node[p + delta];
                }
            }
            node
        });
        WideLayout { nodes, depth: self.depth }
    }
}

#[cfg(test)]
mod tests {
    use glam::Vec3;

    use super::*;
    use crate::Aabb;
    use crate::accel::wide::output::tests::Refs;

    /// A sink holding `refs`, that stores each leaf's primitives as its items.
    fn sink(refs: Vec<u32>) -> Refs {
        Refs { max: 8, refs }
    }

    /// A walked piece of two nodes: its root has a leaf of `prims[0]` in slot 0 and node 1 in
    /// slot 1, which has a leaf of `prims[1]` in slot 3.
    fn walked(prims: [&[u32]; 2], store: &Store<Refs>) -> Pieces<Refs> {
        let mut items = sink(Vec::new());
        let unit = Aabb::new(Vec3::ZERO, Vec3::ONE);
        let mut root = WideNode::EMPTY_NODE;
        let (first, count) = items.leaf(prims[0]);
        root.set_child(0, &unit, LEAF | first, count);
        root.set_child(1, &unit, 1, 0);
        let mut child = WideNode::EMPTY_NODE;
        let (first, count) = items.leaf(prims[1]);
        child.set_child(3, &unit, LEAF | first, count);
        Pieces::walked(WideLayout { nodes: vec![root, child], depth: 2 }, items, store)
    }

    /// A root with a leaf of 9, 9 in slot 1 and the walked pieces in slots 0 and 2, assembled
    /// after a sink holding one item already.
    fn assembled(store: Store<Refs>) -> (WideLayout, Vec<u32>) {
        let unit = Aabb::new(Vec3::ZERO, Vec3::ONE);
        let mut items = sink(Vec::new());
        let mut root = WideNode::EMPTY_NODE;
        let (first, count) = items.leaf(&[9, 9]);
        root.set_child(1, &unit, LEAF | first, count);
        let a = walked([&[1, 2], &[3]], &store);
        let b = walked([&[4], &[5, 6, 7]], &store);
        let pieces = Pieces::joined(root, items, vec![(0, a), (2, b)]);
        let mut after = sink(vec![0]);
        let layout = pieces.assemble(store, &mut after);
        (layout, after.refs)
    }

    #[test]
    fn pieces_assemble_the_same_wherever_they_waited() {
        let roomy = assembled(Store { nodes: Arena::with_capacity(64), items: Arena::with_capacity(64) });
        let (layout, items) = &roomy;
        assert_eq!(layout.depth, 3);
        assert_eq!(items, &[0, 9, 9, 1, 2, 3, 4, 5, 6, 7]);
        let [root, a, a1, b, b1] = layout.nodes[..] else { panic!("{} nodes", layout.nodes.len()) };
        assert_eq!(root.children[..3], [1, LEAF | 1, 3]);
        assert_eq!((&a.children[..2], a1.children[3]), (&[LEAF | 3, 2][..], LEAF | 5));
        assert_eq!((&b.children[..2], b1.children[3]), (&[LEAF | 6, 4][..], LEAF | 7));
        // No room at all, and room for the first piece only: its own vectors keep the rest.
        for (nodes, items) in [(0, 0), (2, 3), (3, 2)] {
            let store = Store { nodes: Arena::with_capacity(nodes), items: Arena::with_capacity(items) };
            assert_eq!(assembled(store), roomy, "room for {nodes} nodes and {items} items");
        }
    }
}
