//! The split candidates of a kd-tree node: Wald and Havran (2006), "On building fast kd-trees for
//! ray tracing, and on doing that in O(N log N)" (IEEE Symposium on Interactive Ray Tracing),
//! section 4.
//!
//! A primitive whose clipped box spans `[a, b]` along an axis gives two events there: it starts
//! at `a` and ends at `b`; a box that is flat along the axis (`a == b`) gives one planar event.
//! The SAH cost can change only at these positions, so they are the only split planes worth
//! evaluating. Events are kept sorted by axis, then position, then kind (ends before planars
//! before starts, so that a sweep sees, at one position, what leaves before what arrives), then
//! primitive index (only so that the order, and so the tree, is deterministic).

use std::cmp::Ordering;

use crate::Aabb;

/// What happens at an event's position.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash)]
#[repr(u8)]
pub enum EventKind {
    /// The primitive's box ends here.
    End = 0,
    /// The primitive's box is flat here.
    Planar = 1,
    /// The primitive's box starts here.
    Start = 2,
}

/// One split candidate: where, along which axis, what, and whose.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Event {
    /// Position along the axis.
    pub pos: f32,
    /// The primitive.
    pub prim: u32,
    /// The axis, 0 to 2.
    pub axis: u8,
    /// Start, end or planar.
    pub kind: EventKind,
}

impl Event {
    /// The sort order of the module documentation. Positions are finite (boxes are checked before
    /// they make events) and never -0 (see [`push_events`]), so `total_cmp` is the numeric order.
    #[inline]
    pub fn order(&self, other: &Event) -> Ordering {
        self.axis
            .cmp(&other.axis)
            .then(self.pos.total_cmp(&other.pos))
            .then(self.kind.cmp(&other.kind))
            .then(self.prim.cmp(&other.prim))
    }
}

/// Appends the events of primitive `prim` whose clipped box is `b` (finite, not empty).
pub fn push_events(out: &mut Vec<Event>, prim: u32, b: &Aabb) {
    for axis in 0..3 {
        // Adding +0 turns -0 into +0, which `total_cmp` would otherwise order apart.
        let (lo, hi) = (b.min[axis] + 0.0, b.max[axis] + 0.0);
        let axis = axis as u8;
        if lo == hi {
            out.push(Event { pos: lo, prim, axis, kind: EventKind::Planar });
        } else {
            out.push(Event { pos: lo, prim, axis, kind: EventKind::Start });
            out.push(Event { pos: hi, prim, axis, kind: EventKind::End });
        }
    }
}

/// Sorts events into the order of [`Event::order`].
pub fn sort_events(events: &mut [Event]) {
    events.sort_unstable_by(Event::order);
}

/// Merges two sorted event lists into one sorted list, in linear time.
pub fn merge_events(a: Vec<Event>, b: Vec<Event>) -> Vec<Event> {
    if b.is_empty() {
        return a;
    }
    if a.is_empty() {
        return b;
    }
    let mut out = Vec::with_capacity(a.len() + b.len());
    let (mut i, mut j) = (0, 0);
    while i < a.len() && j < b.len() {
        if a[i].order(&b[j]) != Ordering::Greater {
            out.push(a[i]);
            i += 1;
        } else {
            out.push(b[j]);
            j += 1;
        }
    }
    out.extend_from_slice(&a[i..]);
    out.extend_from_slice(&b[j..]);
    out
}

/// The primitives an event list speaks of, in list order: one per primitive, from its axis-0
/// start or planar event.
pub fn prims_of(events: &[Event]) -> impl Iterator<Item = u32> + '_ {
    events.iter().take_while(|e| e.axis == 0).filter(|e| e.kind != EventKind::End).map(|e| e.prim)
}

#[cfg(test)]
mod tests {
    use glam::Vec3;

    use super::*;

    #[test]
    fn a_box_gives_two_events_per_axis_and_a_flat_side_one() {
        let mut e = Vec::new();
        push_events(&mut e, 4, &Aabb::new(Vec3::new(0.0, 1.0, 2.0), Vec3::new(1.0, 1.0, 3.0)));
        assert_eq!(e.len(), 5);
        assert_eq!(e.iter().filter(|e| e.kind == EventKind::Planar).count(), 1);
        assert!(e.iter().any(|e| e.axis == 1 && e.kind == EventKind::Planar && e.pos == 1.0));
    }

    #[test]
    fn ends_sort_before_planars_before_starts_at_one_position() {
        let mut e = vec![
            Event { pos: 1.0, prim: 0, axis: 0, kind: EventKind::Start },
            Event { pos: 1.0, prim: 1, axis: 0, kind: EventKind::End },
            Event { pos: 0.0, prim: 2, axis: 1, kind: EventKind::Start },
            Event { pos: 1.0, prim: 3, axis: 0, kind: EventKind::Planar },
            Event { pos: 0.5, prim: 4, axis: 0, kind: EventKind::Start },
        ];
        sort_events(&mut e);
        let got: Vec<u32> = e.iter().map(|e| e.prim).collect();
        assert_eq!(got, [4, 1, 3, 0, 2]);
        assert_eq!(prims_of(&e).collect::<Vec<_>>(), [4, 3, 0]);
    }

    #[test]
    fn merging_keeps_the_order() {
        let mut a = Vec::new();
        let mut b = Vec::new();
        for i in 0..20u32 {
            let bx = Aabb::new(Vec3::splat(i as f32 * 0.37 % 3.0), Vec3::splat(i as f32 * 0.37 % 3.0 + 0.5));
            push_events(if i % 3 == 0 { &mut a } else { &mut b }, i, &bx);
        }
        sort_events(&mut a);
        sort_events(&mut b);
        let mut all: Vec<Event> = a.iter().chain(&b).copied().collect();
        sort_events(&mut all);
        assert_eq!(merge_events(a, b), all);
    }
}
