//! Timing: a query set traced by one library on a pool of `n` threads, the rays split into chunks
//! that the threads take in turn; one untimed warm-up run, then `reps` timed runs, and their
//! median. Results are written into buffers allocated once, outside the timed runs.

use std::time::Instant;

use rayon::prelude::*;

use crate::library::{BenchRay, Library, RayResult};

/// Rays per task handed to a thread (a multiple of every packet width).
pub const CHUNK: usize = 1024;

/// The two queries.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum Query {
    /// Closest hit.
    Closest,
    /// Any hit (occlusion).
    Any,
}

impl Query {
    /// Name in tables and the CSV.
    pub fn name(self) -> &'static str {
        match self {
            Query::Closest => "closest",
            Query::Any => "any",
        }
    }
}

/// Where a query's answers go.
pub enum Answers {
    /// Closest hits.
    Closest(Vec<RayResult>),
    /// Any-hit answers.
    Any(Vec<bool>),
}

impl Answers {
    /// A buffer for `n` answers to `query`.
    pub fn new(query: Query, n: usize) -> Self {
        match query {
            Query::Closest => Answers::Closest(vec![RayResult::MISS; n]),
            Query::Any => Answers::Any(vec![false; n]),
        }
    }
}

/// A pool of exactly `threads` worker threads.
pub fn thread_pool(threads: usize) -> anyhow::Result<rayon::ThreadPool> {
    Ok(rayon::ThreadPoolBuilder::new().num_threads(threads).build()?)
}

/// Traces every ray once, on the current rayon pool.
pub fn trace(library: &dyn Library, rays: &[BenchRay], answers: &mut Answers) {
    match answers {
        Answers::Closest(out) => rays
            .par_chunks(CHUNK)
            .zip(out.par_chunks_mut(CHUNK))
            .for_each(|(rays, out)| library.closest_hits(rays, out)),
        Answers::Any(out) => {
            rays.par_chunks(CHUNK).zip(out.par_chunks_mut(CHUNK)).for_each(|(rays, out)| library.any_hits(rays, out))
        }
    }
}

/// Seconds of each timed run.
#[derive(Clone, Debug, PartialEq)]
pub struct Timing {
    /// Every run, in order.
    pub runs: Vec<f64>,
}

impl Timing {
    /// The median run.
    pub fn median(&self) -> f64 {
        median(&self.runs)
    }
}

/// The median of `values` (the mean of the two middle ones for an even count); NaN if empty.
pub fn median(values: &[f64]) -> f64 {
    if values.is_empty() {
        return f64::NAN;
    }
    let mut v = values.to_vec();
    v.sort_by(f64::total_cmp);
    let mid = v.len() / 2;
    if v.len() % 2 == 1 { v[mid] } else { 0.5 * (v[mid - 1] + v[mid]) }
}

/// Warm-up then `reps` timed runs of `query` over `rays` on `pool`; the answers of the last run
/// are left in `answers`.
pub fn time_query(
    pool: &rayon::ThreadPool,
    library: &dyn Library,
    rays: &[BenchRay],
    answers: &mut Answers,
    reps: usize,
) -> Timing {
    pool.install(|| {
        trace(library, rays, answers);
        let runs = (0..reps)
            .map(|_| {
                let start = Instant::now();
                trace(library, rays, answers);
                start.elapsed().as_secs_f64()
            })
            .collect();
        Timing { runs }
    })
}

/// What [`time_build`] measured.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BuildCost {
    /// Median time of the timed builds, in milliseconds.
    pub ms: f64,
    /// How much the process's resident memory grew across the first build, the built structure
    /// alive at the end, in bytes (`None` where the system does not say): what the structure
    /// and whatever the build left mapped cost in memory, measured the same way for every
    /// library, after [`release_free_memory`].
    pub resident_bytes: Option<u64>,
}

/// Gives the memory the allocator holds free back to the system (glibc's `malloc_trim(0)`, which
/// also releases the free pages inside its heaps; nothing elsewhere). A build measured after it
/// faults in every page it uses, where it would otherwise reuse the pages that loading the scene,
/// the brute force and the libraries built before it left free and resident, and read as
/// costing little or nothing: what a library measured later in the run would owe to the ones
/// before it.
pub fn release_free_memory() {
    #[cfg(all(target_os = "linux", target_env = "gnu"))]
    // SAFETY: `malloc_trim` takes no pointer and only releases memory no allocation holds.
    unsafe {
        libc::malloc_trim(0);
    }
}

/// The process's resident memory in bytes, from Linux's `/proc/self/status` (`None` elsewhere).
pub fn resident_bytes() -> Option<u64> {
    parse_resident(&std::fs::read_to_string("/proc/self/status").ok()?)
}

/// The `VmRSS` line of a `/proc/<pid>/status` text, in bytes.
fn parse_resident(status: &str) -> Option<u64> {
    let line = status.lines().find(|l| l.starts_with("VmRSS:"))?;
    let mut words = line["VmRSS:".len()..].split_whitespace();
    let kib: u64 = words.next()?.parse().ok()?;
    (words.next() == Some("kB")).then_some(kib * 1024)
}

/// Runs `build` once untimed (a warm-up: thread pools started, pages mapped; the growth of the
/// resident memory across it is measured, the allocator's free memory given back first), then
/// `reps` times timed, on `pool`; returns the last result with the median time. Each build but
/// the last is dropped before the next starts.
pub fn time_build<T>(
    pool: &rayon::ThreadPool,
    reps: usize,
    mut build: impl FnMut() -> anyhow::Result<T> + Send,
) -> anyhow::Result<(T, BuildCost)>
where
    T: Send,
{
    pool.install(|| {
        let mut times = Vec::with_capacity(reps.max(1));
        release_free_memory();
        let before = resident_bytes();
        let mut last = Some(build()?);
        let resident = resident_bytes().zip(before).map(|(after, before)| after.saturating_sub(before));
        for _ in 0..reps.max(1) {
            drop(last.take());
            let start = Instant::now();
            let built = build()?;
            times.push(start.elapsed().as_secs_f64() * 1e3);
            last = Some(built);
        }
        Ok((last.expect("at least one build"), BuildCost { ms: median(&times), resident_bytes: resident }))
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn resident_memory_is_read_in_bytes() {
        let status = "Name:\tx\nVmPeak:\t  10 kB\nVmRSS:\t    2048 kB\nThreads:\t1\n";
        assert_eq!(parse_resident(status), Some(2048 * 1024));
        assert_eq!(parse_resident("VmRSS: 12 MB\n"), None);
        assert_eq!(parse_resident("Name: x\n"), None);
        // On Linux the process has some; elsewhere nothing is claimed.
        if cfg!(target_os = "linux") {
            assert!(resident_bytes().is_some_and(|b| b > 0));
        }
    }

    /// Memory freed before a build and kept by the allocator does not hide the build's own: the
    /// growth across it counts the pages it fills again.
    #[test]
    #[cfg(all(target_os = "linux", target_env = "gnu"))]
    fn a_build_after_freed_memory_still_shows_its_pages() {
        const PIECE: usize = 64 << 10;
        // 64 MiB in pieces below glibc's threshold for separate mappings, then a fence above
        // them, so that freeing them leaves free pages inside the heap rather than at its top.
        let pieces: Vec<Vec<u8>> = (0..1024).map(|_| vec![1u8; PIECE]).collect();
        let fence = vec![1u8; 4096];
        drop(pieces);
        release_free_memory();
        let before = resident_bytes().expect("Linux says");
        // 32 MiB filled: the free pieces' places, given back and now faulted in again.
        let again: Vec<Vec<u8>> = (0..512).map(|_| vec![1u8; PIECE]).collect();
        let grown = resident_bytes().expect("Linux says").saturating_sub(before);
        assert!(grown >= 24 << 20, "grew by {grown} bytes");
        // Both alive up to the measurement.
        std::hint::black_box((&again, &fence));
    }

    #[test]
    fn medians() {
        assert_eq!(median(&[3.0, 1.0, 2.0]), 2.0);
        assert_eq!(median(&[4.0, 1.0, 2.0, 3.0]), 2.5);
        assert!(median(&[]).is_nan());
    }
}
