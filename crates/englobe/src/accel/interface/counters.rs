//! Work counters: how many nodes a query visited, how many boxes it tested and how many exact
//! primitive tests it made. The last one is the seed report's whole measure (its calls to
//! `getFirstIntersection`).
//!
//! Every structure is generic over [`Counters`]. [`NoCount`] is a zero-sized type whose methods do
//! nothing and inline away, so a query compiled with it costs exactly what it would cost with no
//! counting code at all; [`WorkCounts`] adds the numbers up.

use std::ops::AddAssign;

/// A sink for the work a query does.
pub trait Counters: Default {
    /// One node (or cell) of a structure was visited.
    fn node_visited(&mut self);
    /// `n` ray/box tests were made.
    fn box_tests(&mut self, n: u32);
    /// One exact ray/primitive test was made.
    fn exact_test(&mut self);
    /// Adds another sink's counts to this one (nested queries, such as instances, count into a
    /// sink of their own and are merged afterwards).
    fn merge(&mut self, other: &Self);
}

/// Counts nothing, costs nothing.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct NoCount;

impl Counters for NoCount {
    #[inline(always)]
    fn node_visited(&mut self) {}
    #[inline(always)]
    fn box_tests(&mut self, _n: u32) {}
    #[inline(always)]
    fn exact_test(&mut self) {}
    #[inline(always)]
    fn merge(&mut self, _other: &Self) {}
}

/// Counts every node visit, box test and exact test.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct WorkCounts {
    /// Nodes (or cells) visited.
    pub nodes_visited: u64,
    /// Ray/box tests.
    pub box_tests: u64,
    /// Exact ray/primitive tests.
    pub exact_tests: u64,
}

impl Counters for WorkCounts {
    #[inline(always)]
    fn node_visited(&mut self) {
        self.nodes_visited += 1;
    }
    #[inline(always)]
    fn box_tests(&mut self, n: u32) {
        self.box_tests += n as u64;
    }
    #[inline(always)]
    fn exact_test(&mut self) {
        self.exact_tests += 1;
    }
    #[inline(always)]
    fn merge(&mut self, other: &Self) {
        *self += *other;
    }
}

impl From<NoCount> for WorkCounts {
    /// Nothing was counted: zeros.
    fn from(_: NoCount) -> Self {
        WorkCounts::default()
    }
}

impl AddAssign for WorkCounts {
    fn add_assign(&mut self, o: Self) {
        self.nodes_visited += o.nodes_visited;
        self.box_tests += o.box_tests;
        self.exact_tests += o.exact_tests;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn no_count_is_zero_sized() {
        assert_eq!(std::mem::size_of::<NoCount>(), 0);
    }

    #[test]
    fn work_counts_add_up() {
        let mut a = WorkCounts::default();
        a.node_visited();
        a.box_tests(2);
        a.exact_test();
        let mut b = a;
        b.merge(&a);
        assert_eq!(b, WorkCounts { nodes_visited: 2, box_tests: 4, exact_tests: 2 });
    }
}
