//! The little parallelism the builders need, with and without the `parallel` feature: two
//! closures side by side (rayon's `join`, the fork-join model of Blumofe and Leiserson (1999),
//! "Scheduling Multithreaded Computations by Work Stealing"), and maps over a slice and over its
//! fixed-size pieces.
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

/// The most elements one task of a parallel map takes, for maps in chunks of at least
/// `min_chunk`. Rayon cuts a map into about as many tasks as there are threads, and cuts further
/// only the ones other threads steal: a task already running is never cut, so one that is a
/// quarter of the map can leave the other threads idle for that long at its end (a profile of a
/// two-thread build of 8.7 million triangles showed one thread idle for a tenth of a second at
/// the end of the blocks' filling). Tasks of a few minimal chunks end nearly together.
#[cfg(feature = "parallel")]
fn most(min_chunk: usize) -> usize {
    min_chunk.max(1).saturating_mul(4)
}

/// Fills `out[i] = f(i)` for every index of `out`, in parallel (in chunks of at least `min_chunk`)
/// when the `parallel` feature is on and `out` is long enough to be worth it.
#[inline]
pub fn fill_indexed<T: Send>(out: &mut [T], min_chunk: usize, f: impl Fn(usize) -> T + Sync) {
    #[cfg(feature = "parallel")]
    if out.len() > min_chunk {
        use rayon::prelude::*;
        out.par_iter_mut()
            .with_min_len(min_chunk.max(1))
            .with_max_len(most(min_chunk))
            .enumerate()
            .for_each(|(i, o)| *o = f(i));
        return;
    }
    let _ = min_chunk;
    for (i, o) in out.iter_mut().enumerate() {
        *o = f(i);
    }
}

/// A new vector of `f(i)` for `i` in `0..n`, made in parallel (in chunks of at least
/// `min_chunk`) when the `parallel` feature is on and `n` is large enough. Each thread writes its
/// part of the fresh memory first, so the page faults of a large vector are taken on every core,
/// where filling a vector made by `vec![x; n]` would first take them all on one.
#[inline]
pub fn collect_indexed<T: Send>(n: usize, min_chunk: usize, f: impl Fn(usize) -> T + Sync) -> Vec<T> {
    collect_indexed_into(Vec::new(), n, min_chunk, f)
}

/// [`collect_indexed`] into memory asked to be backed by huge pages before the first value is
/// written ([`crate::geom::huge_pages`]): for the arrays that queries read at random.
pub fn collect_indexed_huge<T: Send>(n: usize, min_chunk: usize, f: impl Fn(usize) -> T + Sync) -> Vec<T> {
    let values = Vec::with_capacity(n);
    crate::geom::huge_pages::advise_vec(&values);
    collect_indexed_into(values, n, min_chunk, f)
}

/// [`collect_indexed`] into `values` (empty), in its own allocation if its capacity suffices.
#[inline]
fn collect_indexed_into<T: Send>(
    mut values: Vec<T>,
    n: usize,
    min_chunk: usize,
    f: impl Fn(usize) -> T + Sync,
) -> Vec<T> {
    #[cfg(feature = "parallel")]
    if n > min_chunk {
        use rayon::prelude::*;
        // `collect_into_vec` keeps the vector's allocation when its capacity suffices.
        (0..n)
            .into_par_iter()
            .with_min_len(min_chunk.max(1))
            .with_max_len(most(min_chunk))
            .map(&f)
            .collect_into_vec(&mut values);
        return values;
    }
    let _ = min_chunk;
    values.extend((0..n).map(f));
    values
}

/// `f` of each of `items`, in order; in parallel, one task per item, when the `parallel` feature
/// is on (for a few large pieces of work).
#[inline]
pub fn map_each<T: Send, R: Send>(items: Vec<T>, f: impl Fn(T) -> R + Sync) -> Vec<R> {
    #[cfg(feature = "parallel")]
    if items.len() > 1 {
        use rayon::prelude::*;
        return items.into_par_iter().map(&f).collect();
    }
    items.into_iter().map(f).collect()
}

/// Runs `f` on every element of `v`, in parallel (in chunks of at least `min_chunk`) when the
/// `parallel` feature is on and `v` is long enough; true if `f` returned true for all of them.
#[inline]
pub fn all_mut<T: Send>(v: &mut [T], min_chunk: usize, f: impl Fn(&mut T) -> bool + Sync) -> bool {
    #[cfg(feature = "parallel")]
    if v.len() > min_chunk {
        use rayon::prelude::*;
        return v
            .par_iter_mut()
            .with_min_len(min_chunk.max(1))
            .with_max_len(most(min_chunk))
            .map(&f)
            .reduce(|| true, |a, b| a & b);
    }
    let _ = min_chunk;
    v.iter_mut().fold(true, |ok, x| f(x) & ok)
}

/// `f` of each `chunk`-long piece of `v` (the last one shorter), in order; the pieces run in
/// parallel when the `parallel` feature is on. The pieces depend on `chunk` alone, never on the
/// threads, so the result is the same either way.
#[inline]
pub fn map_chunks_mut<T: Send, R: Send>(v: &mut [T], chunk: usize, f: impl Fn(&mut [T]) -> R + Sync) -> Vec<R> {
    let chunk = chunk.max(1);
    #[cfg(feature = "parallel")]
    if v.len() > chunk {
        use rayon::prelude::*;
        return v.par_chunks_mut(chunk).with_max_len(1).map(&f).collect();
    }
    v.chunks_mut(chunk).map(f).collect()
}

/// `f` of each `chunk`-long piece of `v` (the last one shorter), in order, as
/// [`map_chunks_mut`] does for a slice it may change.
#[inline]
pub fn map_chunks<T: Sync, R: Send>(v: &[T], chunk: usize, f: impl Fn(&[T]) -> R + Sync) -> Vec<R> {
    let chunk = chunk.max(1);
    #[cfg(feature = "parallel")]
    if v.len() > chunk {
        use rayon::prelude::*;
        return v.par_chunks(chunk).with_max_len(1).map(&f).collect();
    }
    v.chunks(chunk).map(f).collect()
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
        assert_eq!(collect_indexed(100_000, 1024, |i| (i as u64 * 2_654_435_761) % 1000), out);
        let mut keyed: Vec<(u64, usize)> = out.iter().copied().zip(0..).collect();
        sort_unstable_by_key(&mut keyed, |&(v, i)| (v, i));
        assert!(keyed.windows(2).all(|w| w[0] < w[1]));
        assert_eq!(join(|| 1, || 2), (1, 2));
        // Pieces in order, whatever the threads.
        let mut v: Vec<u32> = (0..10_000).collect();
        let firsts = map_chunks_mut(&mut v, 3000, |c| c[0]);
        assert_eq!(firsts, [0, 3000, 6000, 9000]);
        assert_eq!(map_chunks(&v, 700, |c| c.len()), [[700; 14].as_slice(), &[200]].concat());
        assert!(map_chunks(&[] as &[u32], 7, |c| c.len()).is_empty());
    }

    #[test]
    fn values_on_huge_pages_are_the_values() {
        // Below the size of a huge page, and above it (24 MB: the advice is given).
        for n in [0, 5, 100_000, 1_500_000] {
            let f = |i: usize| [i as u64, (i as u64).wrapping_mul(2_654_435_761)];
            let huge = collect_indexed_huge(n, 1024, f);
            assert!(huge.capacity() >= n);
            assert_eq!(huge, collect_indexed(n, 1024, f), "{n} values");
        }
    }
}
