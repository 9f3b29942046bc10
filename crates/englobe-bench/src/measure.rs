//! Timing: a query set traced by each library on a pool of `n` threads, the rays split into chunks
//! that the threads take in turn; `reps` rounds in which the libraries take turns, each with an
//! untimed warm-up run and a timed one, and each library's median. Results are written into
//! buffers allocated once, outside the timed runs.

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

/// `reps` rounds in which every library traces `rays` once untimed, then once timed, on `pool`:
/// library `i`'s answers go to `answers[i]` (the last run's are left there), its timing is entry
/// `i` of the result. The libraries take turns within each round, each starting one round in
/// turn, so that the machine's other work, which comes and goes over seconds, falls on every
/// library's runs alike rather than on the one whose runs it met: the ratios between libraries of
/// one cell are what a run is for. The untimed run before each timed one brings the library's
/// structure back into the caches the others' turns took it out of, as one library's runs one
/// after another would find it (without it, the short runs of primary rays measured mostly cold
/// caches: `docs/performance.md`).
pub fn time_queries(
    pool: &rayon::ThreadPool,
    libraries: &[&dyn Library],
    rays: &[BenchRay],
    answers: &mut [Answers],
    reps: usize,
) -> Vec<Timing> {
    assert_eq!(libraries.len(), answers.len(), "one answer buffer per library");
    pool.install(|| {
        let n = libraries.len();
        let mut runs = vec![Vec::with_capacity(reps); n];
        for round in 0..reps {
            for turn in 0..n {
                let i = (round + turn) % n;
                trace(libraries[i], rays, &mut answers[i]);
                let start = Instant::now();
                trace(libraries[i], rays, &mut answers[i]);
                runs[i].push(start.elapsed().as_secs_f64());
            }
        }
        runs.into_iter().map(|runs| Timing { runs }).collect()
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
    /// library.
    pub resident_bytes: Option<u64>,
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
/// resident memory across it is measured), then `reps` times timed, on `pool`; returns the last
/// result with the median time. Each build but the last is dropped before the next starts.
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

    /// A library that records, in a log shared by all, which one traced and when, and answers
    /// every ray with its own number.
    struct Logged {
        id: u32,
        log: std::sync::Arc<std::sync::Mutex<Vec<u32>>>,
    }

    impl Library for Logged {
        fn structure(&self) -> String {
            format!("logged {}", self.id)
        }

        fn closest_hits(&self, rays: &[BenchRay], out: &mut [RayResult]) {
            self.log.lock().unwrap().push(self.id);
            for (o, _) in out.iter_mut().zip(rays) {
                *o = RayResult::hit(1.0, self.id);
            }
        }

        fn any_hits(&self, _: &[BenchRay], out: &mut [bool]) {
            out.fill(self.id % 2 == 1);
        }
    }

    #[test]
    fn libraries_take_turns_and_keep_their_own_answers() {
        let log = std::sync::Arc::new(std::sync::Mutex::new(Vec::new()));
        let libraries: Vec<Logged> = (0..3).map(|id| Logged { id, log: log.clone() }).collect();
        let dyn_libraries: Vec<&dyn Library> = libraries.iter().map(|l| l as &dyn Library).collect();
        // One chunk of rays, so that each trace is one call.
        let rays = vec![BenchRay::new(englobe::Vec3::ZERO, englobe::Vec3::X); CHUNK];
        let mut answers: Vec<Answers> = (0..3).map(|_| Answers::new(Query::Closest, rays.len())).collect();
        let pool = thread_pool(1).unwrap();
        let timings = time_queries(&pool, &dyn_libraries, &rays, &mut answers, 4);
        assert!(timings.iter().all(|t| t.runs.len() == 4));
        // Four rounds, each library first in one round in turn, each run after an untimed one.
        assert_eq!(*log.lock().unwrap(), [0, 0, 1, 1, 2, 2, 1, 1, 2, 2, 0, 0, 2, 2, 0, 0, 1, 1, 0, 0, 1, 1, 2, 2]);
        for (id, answers) in answers.iter().enumerate() {
            let Answers::Closest(out) = answers else { panic!("closest answers") };
            assert!(out.iter().all(|r| r.prim == id as u32), "library {id}'s answers are its own");
        }
    }

    #[test]
    fn medians() {
        assert_eq!(median(&[3.0, 1.0, 2.0]), 2.0);
        assert_eq!(median(&[4.0, 1.0, 2.0, 3.0]), 2.5);
        assert!(median(&[]).is_nan());
    }
}
