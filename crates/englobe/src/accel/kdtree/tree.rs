//! The kd-tree's data: its build parameters ([`KdTreeParams`]), its 8-byte nodes ([`KdNode`])
//! and the tree ([`KdTree`]), apart from the code that builds, walks and checks them.

use crate::Aabb;

/// Deepest tree built, whatever the parameters say: it bounds the traversal stack.
pub const MAX_DEPTH: u32 = 64;

/// Build parameters. The defaults are those the measurements of `docs/accelerators.md` use.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct KdTreeParams {
    /// SAH cost of traversing one interior node, relative to [`KdTreeParams::intersection_cost`].
    /// A node step here is a subtraction, a multiplication and two comparisons, an exact test a
    /// watertight triangle test: the default ratio of 1 to 20 is Wald and Havran's 15 to 20 moved
    /// towards pbrt's 1 to 80, where the exact tests per ray on real meshes stop improving (see
    /// `docs/accelerators.md`).
    pub traversal_cost: f32,
    /// SAH cost of one exact primitive test.
    pub intersection_cost: f32,
    /// Fraction of a split's cost forgiven when one side holds no primitive (Wald and Havran's
    /// `1 - lambda`): it favours cutting off empty space, which rays then cross for free.
    pub empty_bonus: f32,
    /// Deepest leaf; `None` for `8 + 1.3 log2(N)` (pbrt's rule). At most [`MAX_DEPTH`].
    pub max_depth: Option<u32>,
    /// Nodes with this many primitives or fewer become leaves without looking for a split. The
    /// default, 0, leaves it to the SAH, which goes on cutting empty space off a single primitive's
    /// cell while that pays (pbrt's 1 stops at one primitive in whatever cell it has).
    pub leaf_size: u32,
    /// Skip primitives a query has already tested in an earlier leaf (see
    /// [`crate::accel::interface::mailbox`]); off only to measure what it saves.
    pub mailbox: bool,
}

impl Default for KdTreeParams {
    fn default() -> Self {
        KdTreeParams {
            traversal_cost: 1.0,
            intersection_cost: 20.0,
            empty_bonus: 0.2,
            max_depth: None,
            leaf_size: 0,
            mailbox: true,
        }
    }
}

impl KdTreeParams {
    /// The depth limit for `n` primitives.
    pub fn depth_limit(&self, n: usize) -> u32 {
        let automatic = || (8.0 + 1.3 * (n.max(1) as f64).log2()).round() as u32;
        self.max_depth.unwrap_or_else(automatic).min(MAX_DEPTH)
    }
}

/// One node of a [`KdTree`]: 8 bytes.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[repr(C)]
pub struct KdNode {
    /// Interior node: the split position's bits. Leaf: offset of its list in
    /// [`KdTree::leaf_lists`].
    pub(super) data: u32,
    /// Low two bits: the split axis (0 to 2), or 3 for a leaf. Interior nodes: the index of the
    /// child above the plane in the other 30.
    pub(super) bits: u32,
}

const _: () = assert!(std::mem::size_of::<KdNode>() == 8);

/// Most nodes: interior nodes keep a child's index in 30 bits.
pub const MAX_NODES: usize = 1 << 30;

impl KdNode {
    const LEAF: u32 = 3;

    /// An interior node splitting `axis` at `split`, whose child above the plane is node `above`
    /// (below `MAX_NODES`).
    pub fn interior(axis: usize, split: f32, above: u32) -> Self {
        debug_assert!(axis < 3 && (above as usize) < MAX_NODES);
        KdNode { data: split.to_bits(), bits: (above << 2) | axis as u32 }
    }

    /// A leaf whose list starts at `offset` of [`KdTree::leaf_lists`].
    pub fn leaf(offset: u32) -> Self {
        KdNode { data: offset, bits: Self::LEAF }
    }

    /// True for a leaf.
    #[inline(always)]
    pub fn is_leaf(&self) -> bool {
        self.bits & 3 == Self::LEAF
    }

    /// The split axis of an interior node.
    #[inline(always)]
    pub fn axis(&self) -> usize {
        (self.bits & 3) as usize
    }

    /// The split position of an interior node.
    #[inline(always)]
    pub fn split(&self) -> f32 {
        f32::from_bits(self.data)
    }

    /// The child above the plane of an interior node (the one below is the next node).
    #[inline(always)]
    pub fn above_child(&self) -> usize {
        (self.bits >> 2) as usize
    }

    /// A leaf's offset in [`KdTree::leaf_lists`].
    #[inline(always)]
    pub fn leaf_offset(&self) -> usize {
        self.data as usize
    }
}

/// An SAH kd-tree over primitives' boxes (see the module documentation).
#[derive(Clone, Debug, PartialEq)]
pub struct KdTree {
    pub(super) nodes: Vec<KdNode>,
    /// Leaf lists: a count, then that many primitive indices. Entry 0 is the empty list.
    pub(super) leaf_lists: Vec<u32>,
    pub(super) bounds: Aabb,
    pub(super) depth: u32,
    /// Primitives the tree was built over (the length of the box list).
    pub(super) prim_count: usize,
    pub(super) mailbox: bool,
}
