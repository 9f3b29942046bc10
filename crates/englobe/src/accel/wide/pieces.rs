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
use crate::accel::bvh::build::parallel::collect_indexed;

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
        let nodes = collect_indexed(total as usize, 1 << 10, |i| {
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
