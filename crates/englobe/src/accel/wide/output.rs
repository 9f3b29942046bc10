//! What the makers of wide trees produce: the nodes and their depth ([`WideLayout`]), and where
//! the leaves go ([`LeafSink`]), shared by the conversion from a binary tree
//! ([`super::convert()`]), the direct build ([`super::build`](mod@super::build)) and the storing
//! of their parallel subtrees.

use super::node::WideNode;

/// Where the leaves of a conversion or a build go.
pub trait LeafSink {
    /// Most primitives one leaf may hold (at least 1); its items must then number at most
    /// [`MAX_LEAF_ITEMS`](super::node::MAX_LEAF_ITEMS).
    fn max_prims(&self) -> usize;
    /// Stores a leaf over the primitives `prims` (at most [`LeafSink::max_prims`]); returns the
    /// index of its first item and its number of items.
    fn leaf(&mut self, prims: &[u32]) -> (u32, u8);
    /// What leaves are stored as (primitive references, blocks of triangles).
    type Item: Copy + Send + Sync;
    /// An empty sink like this one, for a subtree made on another thread.
    fn split(&self) -> Self
    where
        Self: Sized;
    /// The items stored so far, in order (those of a [`LeafSink::split`], handed over).
    fn into_items(self) -> Vec<Self::Item>
    where
        Self: Sized;
    /// Appends `items` (a [`LeafSink::split`]'s) after this sink's; returns the index their
    /// first item now has.
    fn append(&mut self, items: &[Self::Item]) -> u32;
}

/// Wide nodes (the root is node 0; none for an empty tree) and the depth: wide nodes on the
/// longest path from the root (0 for an empty tree).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct WideLayout {
    /// The nodes.
    pub nodes: Vec<WideNode>,
    /// Wide nodes on the longest path from the root to a leaf.
    pub depth: u32,
}

#[cfg(test)]
pub(crate) mod tests {
    use super::LeafSink;

    /// Stores primitive references, at most `max` per leaf.
    pub(crate) struct Refs {
        pub(crate) max: usize,
        pub(crate) refs: Vec<u32>,
    }

    impl LeafSink for Refs {
        fn max_prims(&self) -> usize {
            self.max
        }
        fn leaf(&mut self, prims: &[u32]) -> (u32, u8) {
            let first = self.refs.len() as u32;
            self.refs.extend_from_slice(prims);
            (first, prims.len() as u8)
        }
        type Item = u32;
        fn split(&self) -> Self {
            Refs { max: self.max, refs: Vec::new() }
        }
        fn into_items(self) -> Vec<u32> {
            self.refs
        }
        fn append(&mut self, items: &[u32]) -> u32 {
            let first = self.refs.len() as u32;
            self.refs.extend_from_slice(items);
            first
        }
    }
}
