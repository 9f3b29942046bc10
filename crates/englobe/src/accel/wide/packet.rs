//! Packet traversal of the wide BVH: up to sixteen rays
//! ([`PACKET`](super::packet_kernels::PACKET)) walk the tree together, each node's children
//! tested against all of them at once ([`super::packet_kernels`]), each child entered by the rays
//! that enter its box and only by them. This is the packet traversal of Wald, Slusallek,
//! Benthin and Wagner (2001), "Interactive Rendering with Coherent Ray Tracing", with the active
//! mask and per-ray entry distances of Embree's hybrid traversal (Wald et al. 2014): a stack entry
//! keeps each ray's distance into the child, so that a ray which has found a closer hit since the
//! child was pushed leaves it without another test.
//!
//! Coherent rays (a camera's, shadow rays of neighbouring points towards one light) visit nearly
//! the same nodes, so the packet pays for a node once instead of once per ray. Incoherent rays
//! visit the union of their paths: single-ray queries suit them better, and a packet thinned to
//! a couple of rays lets them go on alone, as Embree's hybrid traversal does.
//!
//! A ray's answer does not depend on its companions: it enters exactly the boxes its own query
//! enters (the same slab test, lane by lane), and its leaves are tested by the single-ray leaf
//! test, closest hits kept by the same rule. The walk order only changes how soon closer hits are
//! found.

use std::mem::MaybeUninit;

use super::node::{WIDTH, WideNode, index_of, is_leaf};
use super::packet_kernels::{ChildHits, Lanes, PacketKernel, PacketRays};
use super::traverse::{INLINE_DEPTH, prefetch_children_of};
use crate::accel::Counters;

/// Entries of the stack: seven per level at most, and the deepest level's eight.
const ENTRIES: usize = (WIDTH - 1) * INLINE_DEPTH + 1;

/// A pending child: each ray's entry distance (NaN for rays that do not enter it), its
/// reference and its leaf item count.
#[derive(Clone, Copy, Debug)]
#[repr(C, align(64))]
struct Entry {
    dist: Lanes,
    reference: u32,
    count: u32,
}

/// What the leaves of a wide BVH hold, and how a packet query tests them.
pub trait PacketLeaves<C: Counters> {
    /// Tests the `count` items from `first` for the closest hit of each ray of `rays`, shrinking
    /// their limits.
    fn closest(&mut self, first: u32, count: u32, rays: u32, counters: &mut C);
    /// The rays of `rays` that hit one of the `count` items from `first`.
    fn any(&mut self, first: u32, count: u32, rays: u32, counters: &mut C) -> u32;
    /// How far each ray may still enter a box (see [`super::node::reach`]).
    fn limits(&self) -> &Lanes;
    /// Starts loading the first item from `first` into the cache (a hint).
    fn prefetch(&self, first: u32);
    /// Walks the subtree of the interior node `reference` with each ray of `rays` alone (the
    /// single-ray traversal), for the closest hit or, without `closest`, any hit; returns the
    /// rays that hit something (any hit only).
    fn alone(&mut self, reference: u32, rays: u32, closest: bool, counters: &mut C) -> u32;
}

/// Rays at most that go on alone rather than as a packet: a node test costs the packet about as
/// much as three rays' own tests.
const ALONE: u32 = 2;

/// Whether a packet query can run on a tree of depth `depth` (its stack lives on the call stack;
/// deeper trees, which only degenerate builds make, are walked one ray at a time).
pub fn fits(depth: u32) -> bool {
    depth as usize <= INLINE_DEPTH
}

/// The children of `hits` in `mask`, nearest first, in `order`; returns how many.
#[inline(always)]
fn sorted_children(hits: &ChildHits, mut mask: u32, order: &mut [u8; WIDTH]) -> usize {
    let mut n = 0;
    while mask != 0 {
        let c = mask.trailing_zeros() as u8;
        mask &= mask - 1;
        let mut j = n;
        while j > 0 && hits.near[order[j - 1] as usize] > hits.near[c as usize] {
            order[j] = order[j - 1];
            j -= 1;
        }
        order[j] = c;
        n += 1;
    }
    n
}

/// The closest hit of each ray of `active` (bit per ray of `rays`): walks the tree from the root
/// (node 0 of a non-empty `nodes`), children nearest first by their nearest ray.
///
/// # Safety
/// As [`super::traverse::closest`], and `depth` [`fits`].
#[inline(always)]
pub unsafe fn closest<K: PacketKernel, C: Counters, L: PacketLeaves<C>>(
    kernel: K,
    nodes: &[WideNode],
    rays: &PacketRays,
    active: u32,
    leaves: &mut L,
    counters: &mut C,
) {
    // SAFETY: the caller's guarantee.
    unsafe { walk(kernel, nodes, rays, active, leaves, counters, true) };
}

/// Whether each ray of `active` hits anything: the rays that found an occluder leave the packet;
/// the walk ends when none is left. Returns the rays that hit.
///
/// # Safety
/// As [`closest`].
#[inline(always)]
pub unsafe fn any<K: PacketKernel, C: Counters, L: PacketLeaves<C>>(
    kernel: K,
    nodes: &[WideNode],
    rays: &PacketRays,
    active: u32,
    leaves: &mut L,
    counters: &mut C,
) -> u32 {
    // SAFETY: the caller's guarantee.
    active & !unsafe { walk(kernel, nodes, rays, active, leaves, counters, false) }
}

/// The walk of both queries; returns the rays still in the packet at the end (for any hit, those
/// that found nothing).
///
/// # Safety
/// As [`closest`].
#[inline(always)]
unsafe fn walk<K: PacketKernel, C: Counters, L: PacketLeaves<C>>(
    kernel: K,
    nodes: &[WideNode],
    rays: &PacketRays,
    mut alive: u32,
    leaves: &mut L,
    counters: &mut C,
    closest: bool,
) -> u32 {
    let mut stack = [const { MaybeUninit::<Entry>::uninit() }; ENTRIES];
    let mut len = 0usize;
    let mut hits = ChildHits::NONE;
    let mut order = [0u8; WIDTH];
    let (mut reference, mut count, mut current) = (0u32, 0u32, alive);
    loop {
        if is_leaf(reference) {
            if closest {
                leaves.closest(index_of(reference), count, current, counters);
            } else {
                alive &= !leaves.any(index_of(reference), count, current, counters);
                if alive == 0 {
                    return 0;
                }
            }
        } else if current.count_ones() <= ALONE {
            let found = leaves.alone(reference, current, closest, counters);
            if !closest {
                alive &= !found;
                if alive == 0 {
                    return 0;
                }
            }
        } else {
            debug_assert!((reference as usize) < nodes.len());
            // SAFETY: the caller's guarantee: interior references index `nodes`.
            let node = unsafe { nodes.get_unchecked(reference as usize) };
            for _ in 0..current.count_ones() {
                counters.node_visited();
                counters.box_tests(WIDTH as u32);
            }
            // SAFETY: the caller's guarantee.
            let mask = unsafe { kernel.children(node, rays, current, leaves.limits(), &mut hits) };
            if mask != 0 {
                prefetch_children_of(nodes, node, mask, |first| leaves.prefetch(first));
                let n = sorted_children(&hits, mask, &mut order);
                if !closest {
                    // Occlusion: the farthest first, as the single-ray walk does (see
                    // `super::traverse`).
                    order[..n].reverse();
                }
                // The others pushed last-taken first, the first one taken now.
                for &c in order[1..n].iter().rev() {
                    let c = c as usize;
                    debug_assert!(len < ENTRIES, "the stack holds seven entries per level");
                    // SAFETY: at most seven entries per level of a tree that `fits`, and eight
                    // at the deepest: `ENTRIES` bounds `len`.
                    unsafe { stack.get_unchecked_mut(len) }.write(Entry {
                        dist: hits.dist[c],
                        reference: node.children[c],
                        count: node.counts[c] as u32,
                    });
                    len += 1;
                }
                let c = order[0] as usize;
                (reference, count, current) = (node.children[c], node.counts[c] as u32, hits.rays[c] & alive);
                continue;
            }
        }
        // The next pending child some ray still enters before its closest hit.
        loop {
            if len == 0 {
                return alive;
            }
            len -= 1;
            // SAFETY: entries below `len` were written.
            let e = unsafe { stack.get_unchecked(len).assume_init_ref() };
            // SAFETY: the caller's guarantee.
            let within = unsafe { kernel.within(&e.dist, leaves.limits(), alive) };
            if within != 0 {
                (reference, count, current) = (e.reference, e.count, within);
                break;
            }
        }
    }
}
