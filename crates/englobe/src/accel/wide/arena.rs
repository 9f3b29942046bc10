//! Room that the parallel parts of a build fill as they finish, from any thread: one reservation
//! for the whole build instead of a vector per part.
//!
//! A wide build's parallel subtrees ([`super::pieces`]) each make thousands of nodes and leaf
//! items, all alive until they are stored together at the end. In vectors of their own (tens of
//! kilobytes each, thousands of them), they would be freed together into the allocator's
//! per-thread pools, where glibc's malloc keeps them resident after the build: 30 bytes per
//! triangle more on an 8.7-million-triangle scene (see `docs/performance.md`). Copied into an
//! arena as each subtree is finished, a subtree's own vectors are freed at once, for the next
//! subtree the thread makes to reuse, and the arena is returned whole. Embree's builders
//! allocate their nodes the same way, from large blocks claimed by the threads (Wald et al.
//! 2014, "Embree: A Kernel Framework for Efficient CPU Ray Tracing").

use std::ops::Range;
use std::sync::atomic::{AtomicUsize, Ordering};

/// Room for `capacity` values, claimed in runs by any thread. Its capacity is reserved, not
/// touched: only the pages the runs fill become resident. A run that no longer fits keeps its
/// own vector.
pub(super) struct Arena<T> {
    /// The reservation (its length stays 0: the values live in its spare capacity).
    _storage: Vec<T>,
    /// Its first slot.
    base: *mut T,
    capacity: usize,
    /// Slots claimed so far (past `capacity` once a run has not fit).
    claimed: AtomicUsize,
}

// SAFETY: `base` points into `_storage`, which the arena owns; each slot is written once, in a
// run claimed atomically by one caller alone, and read only through the `Stored` its write
// returned.
unsafe impl<T: Send> Send for Arena<T> {}
unsafe impl<T: Send + Sync> Sync for Arena<T> {}

/// Where a run of values waits: claimed slots of an arena, or a vector of its own.
pub(super) enum Stored<T> {
    Arena(Range<usize>),
    Own(Vec<T>),
}

impl<T: Copy> Arena<T> {
    /// Room for `capacity` values, or for none if the reservation is refused.
    pub(super) fn with_capacity(capacity: usize) -> Self {
        let mut storage = Vec::new();
        let capacity = if storage.try_reserve_exact(capacity).is_ok() { storage.capacity() } else { 0 };
        // Huge pages: a large build's runs fill hundreds of megabytes, a page fault per 4 KiB
        // otherwise (see `crate::geom::huge_pages`); a page that a run touches is resident whole,
        // so at most one huge page more than the runs fill.
        crate::geom::huge_pages::advise_vec(&storage);
        Arena { base: storage.as_mut_ptr(), _storage: storage, capacity, claimed: AtomicUsize::new(0) }
    }

    /// Keeps `values`: copied into the arena if they fit in what is left of it (their vector
    /// is then freed, for the thread's next one to reuse).
    pub(super) fn store(&self, values: Vec<T>) -> Stored<T> {
        let start = self.claimed.fetch_add(values.len(), Ordering::Relaxed);
        if start.checked_add(values.len()).is_none_or(|end| end > self.capacity) {
            return Stored::Own(values);
        }
        // SAFETY: `start..start + len` lies inside the reservation and was claimed by this call
        // alone; `values` does not overlap it.
        unsafe { self.base.add(start).copy_from_nonoverlapping(values.as_ptr(), values.len()) };
        Stored::Arena(start..start + values.len())
    }

    /// The values `stored` keeps.
    pub(super) fn get<'a>(&'a self, stored: &'a Stored<T>) -> &'a [T] {
        match stored {
            // SAFETY: the run was claimed and written by `store` on this arena, and the write
            // happened before this read: the caller holds the `Stored` it returned.
            Stored::Arena(range) => unsafe { std::slice::from_raw_parts(self.base.add(range.start), range.len()) },
            Stored::Own(values) => values,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn runs_fill_the_arena_in_claim_order_and_the_rest_keep_their_own_vectors() {
        let arena = Arena::with_capacity(5);
        let a = arena.store(vec![1, 2, 3]);
        let b = arena.store(vec![4, 5, 6]);
        let c = arena.store(vec![7, 8]);
        let d = arena.store(Vec::new());
        assert!(matches!(a, Stored::Arena(ref r) if *r == (0..3)));
        assert!(matches!(b, Stored::Own(_)), "three values do not fit in the two slots left");
        assert!(matches!(c, Stored::Own(_)), "claims past the end are not given back");
        assert_eq!(
            (arena.get(&a), arena.get(&b), arena.get(&c), arena.get(&d)),
            (&[1, 2, 3][..], &[4, 5, 6][..], &[7, 8][..], &[][..])
        );
    }

    #[test]
    fn threads_storing_at_once_each_get_their_own_values_back() {
        let arena = Arena::with_capacity(4000);
        let stored: Vec<(u32, Stored<u32>)> = std::thread::scope(|scope| {
            let handles: Vec<_> = (0..8u32)
                .map(|t| {
                    let arena = &arena;
                    scope.spawn(move || {
                        (0..100u32).map(|i| (t * 1000 + i, arena.store(vec![t * 1000 + i; 6]))).collect::<Vec<_>>()
                    })
                })
                .collect();
            handles.into_iter().flat_map(|h| h.join().unwrap()).collect()
        });
        assert!(stored.iter().any(|(_, s)| matches!(s, Stored::Own(_))), "4 800 values overflow 4 000 slots");
        for (value, s) in &stored {
            assert_eq!(arena.get(s), &[*value; 6]);
        }
    }
}
