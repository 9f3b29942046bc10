//! The little parallelism the builders need, with and without the `parallel` feature: two
//! closures side by side (rayon's `join`, the fork-join model of Blumofe and Leiserson (1999),
//! "Scheduling Multithreaded Computations by Work Stealing"), and a map over a slice.
//!
//! Without the feature everything runs in order on the calling thread. The builders produce the
//! same tree either way: parallel parts only ever work on disjoint data and are joined in a fixed
//! order.

/// Runs both closures, in parallel when the `parallel` feature is on, and returns both results.
#[inline]
pub fn join<A: Send, B: Send>(a: impl FnOnce() -> A + Send, b: impl FnOnce() -> B + Send) -> (A, B) {
    #[cfg(feature = "parallel")]
    {
        rayon::join(a, b)
    }
    #[cfg(not(feature = "parallel"))]
    {
        (a(), b())
    }
}

/// Fills `out[i] = f(i)` for every index of `out`, in parallel (in chunks of at least `min_chunk`)
/// when the `parallel` feature is on and `out` is long enough to be worth it.
#[inline]
pub fn fill_indexed<T: Send>(out: &mut [T], min_chunk: usize, f: impl Fn(usize) -> T + Sync) {
    #[cfg(feature = "parallel")]
    if out.len() > min_chunk {
        use rayon::prelude::*;
        out.par_iter_mut().with_min_len(min_chunk.max(1)).enumerate().for_each(|(i, o)| *o = f(i));
        return;
    }
    let _ = min_chunk;
    for (i, o) in out.iter_mut().enumerate() {
        *o = f(i);
    }
}

/// Runs `f` on every element of `v`, in parallel (in chunks of at least `min_chunk`) when the
/// `parallel` feature is on and `v` is long enough; true if `f` returned true for all of them.
#[inline]
pub fn all_mut<T: Send>(v: &mut [T], min_chunk: usize, f: impl Fn(&mut T) -> bool + Sync) -> bool {
    #[cfg(feature = "parallel")]
    if v.len() > min_chunk {
        use rayon::prelude::*;
        return v.par_iter_mut().with_min_len(min_chunk.max(1)).map(&f).reduce(|| true, |a, b| a & b);
    }
    let _ = min_chunk;
    v.iter_mut().fold(true, |ok, x| f(x) & ok)
}

/// Sorts `v` (unstably: give keys that are unique, or equal elements that are identical, for a
/// deterministic order), in parallel when the `parallel` feature is on and `v` is long.
#[inline]
pub fn sort_unstable_by_key<T: Send, K: Ord>(v: &mut [T], key: impl Fn(&T) -> K + Sync) {
    #[cfg(feature = "parallel")]
    if v.len() > 1 << 14 {
        use rayon::prelude::*;
        v.par_sort_unstable_by_key(key);
        return;
    }
    v.sort_unstable_by_key(key);
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fill_and_sort_give_the_sequential_result() {
        let mut out = vec![0u64; 100_000];
        fill_indexed(&mut out, 1024, |i| (i as u64 * 2_654_435_761) % 1000);
        assert!(out.iter().enumerate().all(|(i, &v)| v == (i as u64 * 2_654_435_761) % 1000));
        let mut keyed: Vec<(u64, usize)> = out.iter().copied().zip(0..).collect();
        sort_unstable_by_key(&mut keyed, |&(v, i)| (v, i));
        assert!(keyed.windows(2).all(|w| w[0] < w[1]));
        assert_eq!(join(|| 1, || 2), (1, 2));
    }
}
