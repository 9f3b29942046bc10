//! Single-ray traversal of the wide BVH: all eight children of a node tested at once, the hit
//! ones entered nearest first, the others kept on a stack with their entry distances and dropped
//! without another test if a closer hit is found before they are popped. This is the traversal
//! of Wald, Benthin and Boulos (2008), "Getting Rid of Packets: Efficient SIMD Single-Ray
//! Traversal using Multi-branching BVHs", in the form Embree's `BVHNIntersector1` gives it (Wald
//! et al. 2014): no sorting at all when one child or two are hit (the common cases), up to five
//! sorted in registers by compare-and-swap, an insertion sort on the stack for the rest. The swaps
//! are selections, not branches: the order of three children or more is a coin toss for incoherent
//! rays, which a branch predictor loses; two are ordered by a branch, which the coherent rays of a
//! camera predict well (selecting there too cost primary rays 2-4 %, see `docs/performance.md`).
//!
//! Occlusion queries stop at the first occluder and do not sort: they enter the *farthest* child
//! hit first and push the others as they come. A ray's far boxes are where the surfaces that close
//! a scene lie (walls, floors, the far side of a mesh), which nearly every ray that is occluded at
//! all meets; its near boxes hold the small geometry around its origin, which it mostly passes by.
//! Measured against nearest first (the example `triangle_bvh_stats`, and the renderer's `--stats`),
//! it visits 28 % fewer nodes on random rays in the Sponza, 16 % fewer on its shadow rays, and
//! never more on the other meshes and scenes (see `docs/performance.md`). The binary traversal
//! has long used the same rule ([`crate::accel::bvh::ordered`]); the wide one had not. "Farthest"
//! is by where the ray leaves a box ([`NodeKernel::children_exits`]), not where it enters: a box
//! the ray crosses for longer, out to a farther wall, is likelier to hold what stops it than one
//! it enters late and leaves at once (another 2-7 % fewer nodes on random rays, up to 2.4 % on
//! the renderer's shadow rays). The farthest is kept by selection, not by a branch, for the
//! reason the closest-hit walk's sort gives.
//!
//! The traversal is generic over the node test ([`NodeKernel`], one per instruction set) and over
//! what leaves hold ([`Leaves`]: primitive references tested by a closure, or blocks of
//! triangles). The crate's `dispatch` module calls the instance compiled for the structure's instruction set.
//!
//! The stack holds at most seven entries per level of the path from the root, so the tree's
//! recorded depth bounds it: trees up to [`INLINE_DEPTH`] levels deep use an uninitialised array on
//! the call stack (no per-query cost to clear it); deeper ones (only degenerate builds are) a buffer
//! kept per thread and grown once. No query allocates in the steady state.

use std::cell::Cell;
use std::mem::MaybeUninit;

use super::kernels::NodeKernel;
use super::node::{NodeRay, WIDTH, WideNode, index_of, is_leaf, reach};
use crate::accel::Counters;
use crate::geom::prefetch::prefetch;

/// Depth (in wide nodes) up to which the stack lives on the call stack.
pub const INLINE_DEPTH: usize = 32;
/// Entries of the inline stack.
const INLINE_ENTRIES: usize = (WIDTH - 1) * INLINE_DEPTH + 1;

/// A pending child: its reference, its leaf item count, and the distance at which the ray enters
/// its box.
#[derive(Clone, Copy, Debug)]
pub struct Entry {
    reference: u32,
    count: u32,
    t: f32,
}

/// What the leaves of a wide BVH hold, and how a query tests them.
pub trait Leaves<C: Counters> {
    /// What a query prepares for its leaf tests (the triangle test's constants of its ray), once,
    /// at the first leaf it reaches: a ray that reaches none never pays for it. The walk keeps it
    /// in its own frame rather than in the leaves, which the compiler would otherwise copy in and
    /// out at every query, prepared or not.
    type Prepared;
    /// Prepares the leaf tests of this query, in a walk compiled for node kernel `K` (whose
    /// instruction set the preparation may use).
    fn prepare<K: NodeKernel>(&self) -> Self::Prepared;
    /// Tests the `count` items from `first` for the closest hit, shrinking the interval.
    fn closest(&mut self, prepared: &Self::Prepared, first: u32, count: u32, counters: &mut C);
    /// The end of the interval: the closest hit so far, or the ray's `t_max`.
    fn t_max(&self) -> f32;
    /// Whether any of the `count` items from `first` is hit.
    fn any(&mut self, prepared: &Self::Prepared, first: u32, count: u32, counters: &mut C) -> bool;
    /// Decides what [`Leaves::closest`] left undecided (see `triangle_leaves`): called once, when
    /// the walk has ended. Nothing by default.
    #[inline(always)]
    fn settle_closest(&mut self) {}
    /// Whether an item [`Leaves::any`] left undecided is hit: asked once, when the walk has ended
    /// without a hit. None by default.
    #[inline(always)]
    fn settle_any(&mut self) -> bool {
        false
    }
    /// Starts loading the first item from `first` into the cache (a hint; nothing by default).
    #[inline(always)]
    fn prefetch(&self, first: u32) {
        let _ = first;
    }
}

/// Asks for every child of `node` in `mask` (the ones a ray enters), so that their cache misses
/// overlap instead of following one another as the walk reaches them; `leaf` asks for a leaf's
/// first item. A lone child is not asked for: the walk reads it next, so there is nothing for its
/// miss to overlap with. (The single-ray walks ask for each child as they make its entry, in the
/// loop over the mask they run anyway.)
#[inline(always)]
pub(super) fn prefetch_children_of(nodes: &[WideNode], node: &WideNode, mut mask: u32, leaf: impl Fn(u32)) {
    if mask & mask.wrapping_sub(1) == 0 {
        return;
    }
    while mask != 0 {
        let i = take_lowest(&mut mask);
        prefetch_child(nodes, node.children[i], &leaf);
    }
}

/// Asks for one child: a node, or the first item of a leaf through `leaf`.
#[inline(always)]
fn prefetch_child(nodes: &[WideNode], child: u32, leaf: impl Fn(u32)) {
    if is_leaf(child) {
        leaf(index_of(child));
    } else {
        prefetch(nodes, child);
    }
}

/// The entry of child `slot` of `node`, entered at `dist[slot]`, asked for (see
/// [`prefetch_children_of`]) as it is made: [`closest`] makes one only when two children or more
/// are entered, so that the loop over the mask is the one that makes the entries.
#[inline(always)]
fn asked_entry<C: Counters, L: Leaves<C>>(
    nodes: &[WideNode],
    node: &WideNode,
    slot: usize,
    dist: &[f32; WIDTH],
    leaves: &L,
) -> Entry {
    let reference = node.children[slot];
    prefetch_child(nodes, reference, |first| leaves.prefetch(first));
    Entry { reference, count: node.counts[slot] as u32, t: dist[slot] }
}

thread_local! {
    /// The stack of queries on trees deeper than [`INLINE_DEPTH`], reused from query to query. A
    /// query nested inside another's closure finds it taken and uses a fresh one.
    static DEEP_STACK: Cell<Vec<MaybeUninit<Entry>>> = const { Cell::new(Vec::new()) };
}

/// A query's stack: `inline` if the tree is shallow enough, else the thread's deep stack, taken
/// (left empty in its place) and grown to hold `(WIDTH - 1) * depth + 1` entries: each level of the
/// path pushes at most seven, and the deepest briefly holds all eight of its children. Hand a
/// taken stack back with [`give_back`].
///
/// Not a closure-taking helper on purpose: a closure's body is compiled without the caller's
/// `#[target_feature]`s, and then every intrinsic in it becomes a call.
#[inline(always)]
fn stack_for<'a>(
    depth: u32,
    inline: &'a mut [MaybeUninit<Entry>; INLINE_ENTRIES],
    deep: &'a mut Vec<MaybeUninit<Entry>>,
) -> &'a mut [MaybeUninit<Entry>] {
    let needed = (WIDTH - 1) * depth as usize + 1;
    if needed <= INLINE_ENTRIES {
        inline
    } else {
        *deep = DEEP_STACK.with(Cell::take);
        deep.resize(needed.max(deep.len()), MaybeUninit::uninit());
        deep
    }
}

/// Returns a stack taken by [`stack_for`] to the thread, for the next deep query.
#[inline(always)]
fn give_back(deep: Vec<MaybeUninit<Entry>>) {
    if deep.capacity() > 0 {
        DEEP_STACK.with(|kept| kept.set(deep));
    }
}

/// The leaves' prepared state, made now if this is the query's first leaf.
///
/// Not `Option::get_or_insert_with`, for the reason given at [`stack_for`].
#[inline(always)]
fn prepare_once<'p, K: NodeKernel, C: Counters, L: Leaves<C>>(
    slot: &'p mut Option<L::Prepared>,
    leaves: &L,
) -> &'p L::Prepared {
    if slot.is_none() {
        *slot = Some(leaves.prepare::<K>());
    }
    // SAFETY: set just above if it was not.
    unsafe { slot.as_ref().unwrap_unchecked() }
}

/// The lowest slot set in `mask`, cleared from it (`mask` must not be empty).
#[inline(always)]
pub(super) fn take_lowest(mask: &mut u32) -> usize {
    let slot = mask.trailing_zeros() as usize;
    *mask &= *mask - 1;
    slot
}

/// `if first_wanted { first } else { second }`, field by field, without a branch (a whole entry
/// selected at once goes through memory).
#[inline(always)]
fn pick(first_wanted: bool, first: Entry, second: Entry) -> Entry {
    use std::hint::select_unpredictable as select;
    Entry {
        reference: select(first_wanted, first.reference, second.reference),
        count: select(first_wanted, first.count, second.count),
        t: select(first_wanted, first.t, second.t),
    }
}

/// The two entries with the farther one first, as they go on the stack; a tie keeps them in
/// their order (only a strictly nearer second entry is swapped), as an insertion sort does.
#[inline(always)]
fn farther_first(first: Entry, second: Entry) -> (Entry, Entry) {
    let swap = first.t < second.t;
    (pick(swap, second, first), pick(swap, first, second))
}

/// The closest hit: walks the tree from node `start` (0, the root, for a whole query), asking
/// `leaves` to test the leaves the ray reaches, nearest first.
///
/// # Safety
/// As [`NodeKernel::children`]: compiled with the kernel's target features, run on a processor
/// that has them; and every interior child reference in `nodes` indexes `nodes`, as in every tree
/// the builders make (the structures' validators check it).
#[inline(always)]
pub unsafe fn closest<K: NodeKernel, C: Counters, L: Leaves<C>>(
    kernel: K,
    nodes: &[WideNode],
    depth: u32,
    start: u32,
    ray: &NodeRay,
    leaves: &mut L,
    counters: &mut C,
) {
    // SAFETY: the caller's guarantee.
    let kernel = unsafe { kernel.for_ray(ray) };
    let mut inline = [const { MaybeUninit::<Entry>::uninit() }; INLINE_ENTRIES];
    let mut deep = Vec::new();
    let stack = stack_for(depth, &mut inline, &mut deep);
    let mut len = 0usize;
    let mut dist = [0.0f32; WIDTH];
    let mut current = Entry { reference: start, count: 0, t: 0.0 };
    let mut prepared_slot = None;
    // How far a box may begin and still be entered: kept here, where it stays in a register,
    // and made again only when a leaf may have moved the closest hit.
    let mut limit = reach(leaves.t_max());
    'walk: loop {
        {
            if is_leaf(current.reference) {
                let prepared = prepare_once::<K, C, L>(&mut prepared_slot, leaves);
                leaves.closest(prepared, index_of(current.reference), current.count, counters);
                limit = reach(leaves.t_max());
            } else {
                debug_assert!((current.reference as usize) < nodes.len());
                // SAFETY: the caller's guarantee: interior references index `nodes`.
                let node = unsafe { nodes.get_unchecked(current.reference as usize) };
                counters.node_visited();
                counters.box_tests(WIDTH as u32);
                // SAFETY: the caller's guarantee.
                let mut mask = unsafe { kernel.children(node, ray, limit, &mut dist) };
                if mask != 0 {
                    let first = take_lowest(&mut mask);
                    if mask == 0 {
                        // A lone child is not asked for: it is read next.
                        current =
                            Entry { reference: node.children[first], count: node.counts[first] as u32, t: dist[first] };
                        continue;
                    }
                    let a = asked_entry(nodes, node, first, &dist, leaves);
                    let second = take_lowest(&mut mask);
                    let b = asked_entry(nodes, node, second, &dist, leaves);
                    if mask == 0 {
                        let (near, far) = if b.t < a.t { (b, a) } else { (a, b) };
                        stack[len].write(far);
                        len += 1;
                        current = near;
                        continue;
                    }
                    // Three or more: the first five sorted in registers, farthest first (the
                    // order an insertion sort gives, ties kept in slot order); the rest, if any,
                    // pushed above them and sorted in on the stack. The nearest is entered.
                    let third = take_lowest(&mut mask);
                    let c = asked_entry(nodes, node, third, &dist, leaves);
                    let (a, b) = farther_first(a, b);
                    let (b, c) = farther_first(b, c);
                    let (a, b) = farther_first(a, b);
                    if mask == 0 {
                        stack[len].write(a);
                        stack[len + 1].write(b);
                        len += 2;
                        current = c;
                        continue;
                    }
                    let fourth = take_lowest(&mut mask);
                    let d = asked_entry(nodes, node, fourth, &dist, leaves);
                    let (c, d) = farther_first(c, d);
                    let (b, c) = farther_first(b, c);
                    let (a, b) = farther_first(a, b);
                    if mask == 0 {
                        stack[len].write(a);
                        stack[len + 1].write(b);
                        stack[len + 2].write(c);
                        len += 3;
                        current = d;
                        continue;
                    }
                    let fifth = take_lowest(&mut mask);
                    let e = asked_entry(nodes, node, fifth, &dist, leaves);
                    let (d, e) = farther_first(d, e);
                    let (c, d) = farther_first(c, d);
                    let (b, c) = farther_first(b, c);
                    let (a, b) = farther_first(a, b);
                    stack[len].write(a);
                    stack[len + 1].write(b);
                    stack[len + 2].write(c);
                    stack[len + 3].write(d);
                    if mask == 0 {
                        len += 4;
                        current = e;
                        continue;
                    }
                    let base = len;
                    stack[len + 4].write(e);
                    len += 5;
                    while mask != 0 {
                        let i = take_lowest(&mut mask);
                        stack[len].write(asked_entry(nodes, node, i, &dist, leaves));
                        len += 1;
                    }
                    for i in base + 5..len {
                        // SAFETY: entries below `len` were written.
                        let e = unsafe { stack[i].assume_init() };
                        let mut j = i;
                        while j > base && unsafe { stack[j - 1].assume_init() }.t < e.t {
                            stack[j] = stack[j - 1];
                            j -= 1;
                        }
                        stack[j].write(e);
                    }
                    len -= 1;
                    // SAFETY: written above.
                    current = unsafe { stack[len].assume_init() };
                    continue;
                }
            }
            // Next pending child the ray still enters before the closest hit.
            loop {
                if len == 0 {
                    break 'walk;
                }
                len -= 1;
                // SAFETY: entries below `len` were written.
                let e = unsafe { stack[len].assume_init() };
                if e.t <= limit {
                    current = e;
                    break;
                }
            }
        }
    }
    give_back(deep);
    leaves.settle_closest();
}

/// Whether any leaf item is hit, from node `start`: stops at the first one `leaves` reports.
///
/// # Safety
/// As [`closest`].
#[inline(always)]
#[allow(clippy::too_many_arguments)]
pub unsafe fn any<K: NodeKernel, C: Counters, L: Leaves<C>>(
    kernel: K,
    nodes: &[WideNode],
    depth: u32,
    start: u32,
    ray: &NodeRay,
    limit: f32,
    leaves: &mut L,
    counters: &mut C,
) -> bool {
    // SAFETY: the caller's guarantee.
    let kernel = unsafe { kernel.for_ray(ray) };
    let mut inline = [const { MaybeUninit::<Entry>::uninit() }; INLINE_ENTRIES];
    let mut deep = Vec::new();
    let stack = stack_for(depth, &mut inline, &mut deep);
    let mut len = 0usize;
    let mut dist = [0.0f32; WIDTH];
    let mut current = Entry { reference: start, count: 0, t: 0.0 };
    let mut prepared_slot = None;
    let hit = 'walk: loop {
        {
            if is_leaf(current.reference) {
                let prepared = prepare_once::<K, C, L>(&mut prepared_slot, leaves);
                if leaves.any(prepared, index_of(current.reference), current.count, counters) {
                    break 'walk true;
                }
            } else {
                debug_assert!((current.reference as usize) < nodes.len());
                // SAFETY: the caller's guarantee: interior references index `nodes`.
                let node = unsafe { nodes.get_unchecked(current.reference as usize) };
                counters.node_visited();
                counters.box_tests(WIDTH as u32);
                // SAFETY: the caller's guarantee. (`dist`: where the ray leaves each child.)
                let mut mask = unsafe { kernel.children_exits(node, ray, limit, &mut dist) };
                if mask != 0 {
                    // The farthest child first (the likeliest to hold an occluder: see the
                    // module documentation), the others pushed as they come; each asked for as
                    // it is met (see `prefetch_children_of`), unless it is the only one.
                    let mut farthest = take_lowest(&mut mask);
                    if mask != 0 {
                        prefetch_child(nodes, node.children[farthest], |first| leaves.prefetch(first));
                    }
                    while mask != 0 {
                        let i = take_lowest(&mut mask);
                        prefetch_child(nodes, node.children[i], |first| leaves.prefetch(first));
                        // Selected, not branched on: which child reaches farther is a coin toss.
                        let further = dist[i] > dist[farthest];
                        let push = std::hint::select_unpredictable(further, farthest, i);
                        farthest = std::hint::select_unpredictable(further, i, farthest);
                        stack[len].write(Entry {
                            reference: node.children[push],
                            count: node.counts[push] as u32,
                            t: 0.0,
                        });
                        len += 1;
                    }
                    current = Entry { reference: node.children[farthest], count: node.counts[farthest] as u32, t: 0.0 };
                    continue;
                }
            }
            if len == 0 {
                break 'walk false;
            }
            len -= 1;
            // SAFETY: entries below `len` were written.
            current = unsafe { stack[len].assume_init() };
        }
    };
    give_back(deep);
    hit || leaves.settle_any()
}
