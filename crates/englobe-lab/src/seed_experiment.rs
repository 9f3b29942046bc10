//! The seed report's experiment (`englobe experiment seed`): its four tests (see
//! [`crate::seed_report`]) rendered with every accelerator of `AccelKind::ALL`, then one table of
//! rays cast, exact intersection tests, reduction against brute force and render time, beside the
//! report's own figures; then the report's claims checked against ours, and whether every
//! accelerator drew the same image.

use std::path::{Path, PathBuf};

use englobe::AccelKind;
use englobe_render::write_image;
use englobe_scene::parse_scene;
use serde::Serialize;

use crate::error::LabError;
use crate::measure::{MAX_TIMED_RUNS, MIN_TIMED_SECONDS, RenderSettings, build, compare_films, render, thread_pool};
use crate::report::{grouped, write_json};
use crate::seed_report::{ReportFigures, SEED_TESTS};

/// What to run.
#[derive(Clone, Debug, Default)]
pub struct SeedOptions {
    /// Image width and height in pixels (default: the scenes' own, 512, like the report's).
    pub size: Option<u32>,
    /// Only these tests (1 to 4; default: all).
    pub tests: Vec<u32>,
    /// Only these accelerators (default: all); brute force (none) always runs, as the reference,
    /// and the lower bound (`bound`) last, as the yardstick.
    pub accel: Vec<AccelKind>,
    /// Worker threads (default: all cores).
    pub threads: Option<u32>,
    /// Write every image rendered into this folder, as testN-ACCEL.png.
    pub images: Option<PathBuf>,
}

/// One line of the table: one test rendered with one accelerator.
#[derive(Clone, Debug, Serialize)]
pub struct SeedRow {
    /// The report's test number.
    pub test: u32,
    /// The scene file.
    pub scene: &'static str,
    /// The structure's name.
    pub accel: &'static str,
    /// Primitives in the structure.
    pub primitives: usize,
    /// Rays cast, over all kinds.
    pub rays: u64,
    /// Exact intersection tests: the report's measure.
    pub exact_tests: u64,
    /// Nodes visited.
    pub nodes_visited: u64,
    /// Box tests.
    pub box_tests: u64,
    /// Fewer exact tests than brute force, in percent.
    pub reduction_percent: f64,
    /// Seconds to build the world.
    pub build_seconds: f64,
    /// Best wall-clock time of `timed_runs` renders (counting on).
    pub seconds: f64,
    /// Renders timed.
    pub timed_runs: u32,
    /// The image is bit for bit brute force's.
    pub image_identical: bool,
    /// Pixels that differ from brute force's.
    pub differing_pixels: usize,
    /// The report's count for this row (brute force: before; bvh-seed: after).
    pub report_exact_tests: Option<f64>,
    /// The reduction the report states (bvh-seed rows).
    pub report_reduction_percent: Option<f64>,
}

/// One of the report's claims, and whether our measurements bear it out.
#[derive(Clone, Debug, Serialize)]
pub struct Check {
    /// The claim, with our figures.
    pub claim: String,
    /// Whether it holds.
    pub holds: bool,
    /// When it does not hold, why, in words: where and by how much our figures miss it.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub why_not: Option<String>,
}

impl Check {
    /// A claim that holds or not; `why_not` is kept only when it does not.
    fn new(claim: String, holds: bool, why_not: impl FnOnce() -> String) -> Self {
        let why_not = (!holds).then(why_not);
        Check { claim, holds, why_not }
    }
}

/// The experiment's results, as `--json` writes them.
#[derive(Clone, Debug, Serialize)]
pub struct SeedExperiment {
    /// Always `seed`.
    pub experiment: &'static str,
    /// Image width of the last test run.
    pub width: u32,
    /// Image height of the last test run.
    pub height: u32,
    /// Samples per pixel of the last test run.
    pub samples: u32,
    /// Worker threads.
    pub threads: usize,
    /// One row per test and accelerator, in that order.
    pub rows: Vec<SeedRow>,
    /// The report's claims, checked.
    pub checks: Vec<Check>,
}

/// Runs the experiment; `progress` is told what is being rendered.
pub fn run_seed(options: &SeedOptions, progress: &mut dyn FnMut(&str)) -> Result<SeedExperiment, LabError> {
    let mut kinds: Vec<AccelKind> =
        AccelKind::ALL.iter().copied().filter(|k| options.accel.is_empty() || options.accel.contains(k)).collect();
    if !kinds.contains(&AccelKind::None) {
        kinds.insert(0, AccelKind::None);
    }
    // The yardstick row: the fewest exact tests any BVH over the same spheres could make.
    kinds.push(AccelKind::Bound);
    if let Some(dir) = &options.images {
        std::fs::create_dir_all(dir).map_err(|source| LabError::CreateDir { path: dir.clone(), source })?;
    }
    let pool = thread_pool(options.threads)?;
    let mut rows = Vec::new();
    let (mut width, mut height, mut samples) = (0, 0, 0);
    for test in SEED_TESTS.iter().filter(|t| options.tests.is_empty() || options.tests.contains(&t.number)) {
        let scene = parse_scene(test.text, test.file.as_ref())?;
        (width, height, samples) = match options.size {
            Some(s) => (s, s, scene.image.samples),
            None => (scene.image.width, scene.image.height, scene.image.samples),
        };
        let settings = RenderSettings { width, height, samples, count_work: true, stride: 1 };
        let mut reference = None;
        for &kind in &kinds {
            progress(&format!("test {}: rendering with {kind}...", test.number));
            let (world, build_seconds) = build(&scene, kind)?;
            let out = pool.install(|| render(&scene, &world, settings))?;
            // Short renders are timed again and the best time kept: on a busy machine one run of
            // a fraction of a second says little.
            let (mut seconds, mut spent, mut timed_runs) = (out.seconds, out.seconds, 1);
            while spent < MIN_TIMED_SECONDS && timed_runs < MAX_TIMED_RUNS {
                let again = pool.install(|| render(&scene, &world, settings))?.seconds;
                (seconds, spent, timed_runs) = (seconds.min(again), spent + again, timed_runs + 1);
            }
            if let Some(dir) = &options.images {
                write_image(&out.film, &dir.join(format!("test{}-{kind}.png", test.number)))?;
            }
            let total = out.stats.total();
            let reference_film = reference.get_or_insert_with(|| (out.film.clone(), total.exact_tests));
            let (_, differing) = compare_films(&reference_film.0, 1, &out.film, 1);
            let (report_exact_tests, report_reduction_percent) = match (test.report, kind) {
                (ReportFigures::Counts { before, .. }, AccelKind::None) => (Some(before), None),
                (ReportFigures::Counts { after, stated_percent, .. }, AccelKind::BvhSeed) => {
                    (Some(after), Some(stated_percent))
                }
                _ => (None, None),
            };
            rows.push(SeedRow {
                test: test.number,
                scene: test.file,
                accel: kind.name(),
                primitives: world.primitive_count(),
                rays: total.rays,
                exact_tests: total.exact_tests,
                nodes_visited: total.nodes_visited,
                box_tests: total.box_tests,
                reduction_percent: reduction(reference_film.1, total.exact_tests),
                build_seconds,
                seconds,
                timed_runs,
                image_identical: differing == 0,
                differing_pixels: differing,
                report_exact_tests,
                report_reduction_percent,
            });
        }
    }
    let checks = seed_checks(&rows);
    let threads = pool.current_num_threads();
    Ok(SeedExperiment { experiment: "seed", width, height, samples, threads, rows, checks })
}

impl SeedExperiment {
    /// The table: every row beside the report's figures, then what each test holds.
    pub fn table(&self) -> String {
        table(&self.rows, self.width, self.height, self.samples, self.threads)
    }

    /// The report's claims and whether they hold, one a line, under a heading.
    pub fn claims(&self) -> String {
        let mut out = "\nThe report's claims and ours, on our scenes:\n".to_owned();
        for c in &self.checks {
            out += &format!("  [{}] {}\n", if c.holds { "yes" } else { "NO" }, c.claim);
            if let Some(why) = &c.why_not {
                out += &format!("        why not: {why}\n");
            }
        }
        out
    }

    /// Whether every accelerator drew brute force's image on every test.
    pub fn images_identical(&self) -> bool {
        self.rows.iter().all(|r| r.image_identical)
    }

    /// Writes the results as JSON to `path`, atomically.
    pub fn write_json(&self, path: &Path) -> Result<(), LabError> {
        write_json(path, self)
    }
}

/// Fewer exact tests than `before`, in percent.
fn reduction(before: u64, after: u64) -> f64 {
    if before == 0 { 0.0 } else { 100.0 * (1.0 - after as f64 / before as f64) }
}

fn table(rows: &[SeedRow], width: u32, height: u32, samples: u32, threads: usize) -> String {
    let mut out = format!(
        "The seed report's experiments: {width}x{height}, {samples} sample(s) per pixel, Whitted rays, \
         {threads} threads{}.\n\
         Exact tests are the report's measure (calls to the exact intersection function, over all \
         rays); seconds are the wall-clock time of the render with counting on, the best of up to \
         {MAX_TIMED_RUNS} runs for renders under {MIN_TIMED_SECONDS} s.\n\n",
        if cfg!(debug_assertions) { ", debug build (times are not representative)" } else { "" },
    );
    out += &format!(
        "Absolute counts are ours at {width}x{height}, the size run, and the report's at its 512x512: they \
         compare only at 512x512; the reductions (fewer) compare at any size.\n\n"
    );
    out += &format!(
        "{:<4} {:<18} {:>10} {:>14} {:>8} {:>9}  {:<10} | {:>14} {:>8}\n",
        "test",
        "accelerator",
        "rays",
        format!("tests {width}x{height}"),
        "fewer",
        "seconds",
        "image",
        "report 512x512",
        "fewer"
    );
    out += &format!("{}\n", "-".repeat(107));
    for (i, r) in rows.iter().enumerate() {
        if i > 0 && rows[i - 1].test != r.test {
            out.push('\n');
        }
        let reference = r.accel == AccelKind::None.name();
        let fewer = if reference { "-".to_owned() } else { format!("{:.1} %", r.reduction_percent) };
        let image = match (reference, r.image_identical) {
            (true, _) => "reference".to_owned(),
            (false, true) => "identical".to_owned(),
            (false, false) => format!("{} differ", r.differing_pixels),
        };
        let report_tests = r.report_exact_tests.map_or(String::new(), format_report_count);
        let report_fewer = r.report_reduction_percent.map_or(String::new(), |p| format!("{p:.1} %"));
        let words = match (SEED_TESTS[(r.test - 1) as usize].report, reference, r.accel) {
            (ReportFigures::Words { before, .. }, true, _) => before,
            (ReportFigures::Words { after, .. }, false, "bvh-seed") => after,
            _ => "",
        };
        out += &format!(
            "{:<4} {:<18} {:>10} {:>14} {:>8} {:>9.3}  {:<10} | {:>14} {:>8}{}\n",
            r.test,
            r.accel,
            grouped(r.rays),
            grouped(r.exact_tests),
            fewer,
            r.seconds,
            image,
            report_tests,
            report_fewer,
            if words.is_empty() { String::new() } else { format!(" {words}") },
        );
    }
    out.push('\n');
    for test in SEED_TESTS.iter().filter(|t| rows.iter().any(|r| r.test == t.number)) {
        let primitives = rows.iter().find(|r| r.test == test.number).map_or(0, |r| r.primitives);
        out += &format!("test {}: {} ({}, {primitives} spheres)\n", test.number, test.title, test.file);
    }
    out
}

/// The report's counts as it writes them: scientific notation above a million.
pub(crate) fn format_report_count(n: f64) -> String {
    if n >= 1e6 {
        let exponent = n.log10().floor() as i32;
        format!("{:.5}e{exponent}", n / 10f64.powi(exponent))
    } else {
        grouped(n as u64)
    }
}

/// The report's claims, checked on the rows measured (a claim whose rows were not run is left out).
fn seed_checks(rows: &[SeedRow]) -> Vec<Check> {
    let find = |test: u32, accel: AccelKind| rows.iter().find(|r| r.test == test && r.accel == accel.name());
    let mut checks = Vec::new();
    for test in SEED_TESTS {
        if let (ReportFigures::Counts { stated_percent, .. }, Some(seed)) =
            (test.report, find(test.number, AccelKind::BvhSeed))
        {
            checks.push(Check::new(
                format!(
                    "test {}: bvh-seed makes {:.1} % fewer exact tests than none; the report: {stated_percent:.1} %",
                    test.number, seed.reduction_percent
                ),
                seed.reduction_percent >= stated_percent,
                || format!("our reduction is {:.1} points below the report's", stated_percent - seed.reduction_percent),
            ));
        }
    }
    if let (Some(one), Some(four)) = (find(1, AccelKind::BvhSeed), find(4, AccelKind::BvhSeed)) {
        let ratio = four.seconds / one.seconds;
        checks.push(Check::new(
            format!("test 4 renders with bvh-seed in {ratio:.2}x the time of test 1 (less than 2x)"),
            ratio < 2.0,
            || {
                format!(
                    "test 4 took {:.3} s and test 1 {:.3} s; short renders on a busy machine vary by tens of percent \
                     (the exact tests, {} against {}, do not)",
                    four.seconds,
                    one.seconds,
                    grouped(four.exact_tests),
                    grouped(one.exact_tests)
                )
            },
        ));
    }
    if let (Some(one), Some(four)) = (find(1, AccelKind::None), find(4, AccelKind::None)) {
        let ratio = four.seconds / one.seconds;
        checks.push(Check::new(
            format!("test 4 renders with none {ratio:.0}x slower than test 1 (at least 100x)"),
            ratio >= 100.0,
            || {
                format!(
                    "brute force's exact tests grow {:.0}x from test 1 to test 4, its time only {ratio:.0}x: the \
                     work that does not grow with the spheres (shading, writing the film) weighs more at this size",
                    four.exact_tests as f64 / one.exact_tests.max(1) as f64
                )
            },
        ));
    }
    let tests: Vec<u32> =
        SEED_TESTS.iter().map(|t| t.number).filter(|&n| find(n, AccelKind::BvhSeed).is_some()).collect();
    let ordered: Vec<(u64, u64)> = tests
        .iter()
        .filter_map(|&n| {
            Some((find(n, AccelKind::BvhSeed)?.exact_tests, find(n, AccelKind::BvhSeedOrdered)?.exact_tests))
        })
        .collect();
    if !ordered.is_empty() {
        let named: Vec<(u32, u64, u64)> = tests.iter().zip(&ordered).map(|(&t, &(s, o))| (t, o, s)).collect();
        checks.push(Check::new(
            format!(
                "bvh-seed-ordered needs fewer exact tests than bvh-seed on every test ({})",
                ordered
                    .iter()
                    .map(|(s, o)| format!("{} vs {}", grouped(*o), grouped(*s)))
                    .collect::<Vec<_>>()
                    .join(", ")
            ),
            ordered.iter().all(|(s, o)| o < s),
            || not_fewer(&named, "bvh-seed-ordered", "bvh-seed"),
        ));
    }
    // The quality BVHs against the report's tree with the ordered traversal, and the reductions
    // they aim at (80 % on test 1, 99.5 % on test 3).
    for kind in [AccelKind::BvhSah, AccelKind::BvhPloc, AccelKind::BvhSweep] {
        let named: Vec<(u32, u64, u64)> = SEED_TESTS
            .iter()
            .filter_map(|t| {
                Some((
                    t.number,
                    find(t.number, kind)?.exact_tests,
                    find(t.number, AccelKind::BvhSeedOrdered)?.exact_tests,
                ))
            })
            .collect();
        if !named.is_empty() {
            checks.push(Check::new(
                format!(
                    "{kind} needs fewer exact tests than bvh-seed-ordered on every test ({})",
                    named
                        .iter()
                        .map(|(_, q, o)| format!("{} vs {}", grouped(*q), grouped(*o)))
                        .collect::<Vec<_>>()
                        .join(", ")
                ),
                named.iter().all(|(_, q, o)| q < o),
                || {
                    let mut why = not_fewer(&named, kind.name(), "bvh-seed-ordered")
                        + "; the surface area heuristic minimises the expected cost of rays spread evenly over \
                           space, not of one camera's rays";
                    let gaps: Option<Vec<f64>> = named
                        .iter()
                        .map(|&(t, _, o)| {
                            Some(100.0 * (o as f64 / find(t, AccelKind::Bound)?.exact_tests as f64 - 1.0))
                        })
                        .collect();
                    if let Some(worst) = gaps.and_then(|g| g.into_iter().reduce(f64::max)) {
                        why += &format!(
                            ", and bvh-seed-ordered is already within {worst:.1} % of the bound on every test"
                        );
                    }
                    why
                },
            ));
        }
        for (test, aim) in [(1, 80.0), (3, 99.5)] {
            if let Some(row) = find(test, kind) {
                checks.push(Check::new(
                    format!(
                        "test {test}: {kind} makes {:.1} % fewer exact tests than none (aim: {aim} %)",
                        row.reduction_percent
                    ),
                    row.reduction_percent >= aim,
                    || format!("{:.1} points short of the aim", aim - row.reduction_percent),
                ));
            }
        }
    }
    // Every BVH against the fewest exact tests any BVH could make (the `bound` row).
    for test in SEED_TESTS {
        let Some(bound) = find(test.number, AccelKind::Bound) else { continue };
        let above: Vec<String> = rows
            .iter()
            .filter(|r| r.test == test.number && r.accel.starts_with("bvh"))
            .map(|r| format!("{} +{:.1} %", r.accel, 100.0 * (r.exact_tests as f64 / bound.exact_tests as f64 - 1.0)))
            .collect();
        let below: Vec<String> = rows
            .iter()
            .filter(|r| r.test == test.number && r.accel.starts_with("bvh") && r.exact_tests < bound.exact_tests)
            .map(|r| format!("{} with {}", r.accel, grouped(r.exact_tests)))
            .collect();
        checks.push(Check::new(
            format!(
                "test {}: no BVH makes fewer exact tests than the bound, {}; above it: {}",
                test.number,
                grouped(bound.exact_tests),
                above.join(", ")
            ),
            below.is_empty(),
            || format!("below the bound: {}; the bound or that structure's counting is wrong", below.join(", ")),
        ));
    }
    let differ: Vec<String> = rows
        .iter()
        .filter(|r| !r.image_identical)
        .map(|r| format!("test {} with {} ({} pixels)", r.test, r.accel, r.differing_pixels))
        .collect();
    checks.push(Check::new(
        "every accelerator draws the same image as brute force on every test".to_owned(),
        differ.is_empty(),
        || format!("images differ: {}", differ.join(", ")),
    ));
    checks
}

/// Where `ours` (the first count of each `(test, ours, theirs)`) is not fewer than `theirs`, in
/// words.
fn not_fewer(counts: &[(u32, u64, u64)], ours: &str, theirs: &str) -> String {
    let misses: Vec<String> = counts
        .iter()
        .filter(|(_, o, t)| o >= t)
        .map(|&(test, o, t)| {
            if o == t {
                format!("on test {test} both make {}", grouped(o))
            } else {
                format!(
                    "on test {test} {ours} makes {:.1} % more ({} against {})",
                    100.0 * (o as f64 / t as f64 - 1.0),
                    grouped(o),
                    grouped(t)
                )
            }
        })
        .collect();
    format!("not fewer than {theirs} everywhere: {}", misses.join("; "))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn row(test: u32, accel: AccelKind, exact_tests: u64, reduction_percent: f64) -> SeedRow {
        SeedRow {
            test,
            scene: "t.toml",
            accel: accel.name(),
            primitives: 7,
            rays: 100,
            exact_tests,
            nodes_visited: 0,
            box_tests: 0,
            reduction_percent,
            build_seconds: 0.0,
            seconds: 0.1,
            timed_runs: 1,
            image_identical: true,
            differing_pixels: 0,
            report_exact_tests: None,
            report_reduction_percent: None,
        }
    }

    #[test]
    fn every_claim_that_fails_says_why_in_words() {
        let mut rows = vec![
            row(1, AccelKind::None, 1000, 0.0),
            row(1, AccelKind::BvhSeed, 900, 10.0),
            row(1, AccelKind::BvhSeedOrdered, 500, 50.0),
            row(1, AccelKind::BvhSah, 510, 49.0),
            row(1, AccelKind::Bound, 495, 50.5),
            row(2, AccelKind::None, 1000, 0.0),
            row(2, AccelKind::BvhSeed, 20, 98.0),
            row(2, AccelKind::BvhSeedOrdered, 20, 98.0),
            row(2, AccelKind::BvhSah, 20, 98.0),
            row(2, AccelKind::Bound, 20, 98.0),
        ];
        rows[3].image_identical = false;
        rows[3].differing_pixels = 3;
        let checks = seed_checks(&rows);
        assert!(checks.iter().any(|c| !c.holds), "the rows make claims fail");
        for c in &checks {
            assert_eq!(c.holds, c.why_not.is_none(), "{}: {:?}", c.claim, c.why_not);
        }
        let why = |start: &str| {
            checks.iter().find(|c| c.claim.starts_with(start)).and_then(|c| c.why_not.clone()).unwrap_or_default()
        };
        assert_eq!(why("test 1: bvh-seed makes"), "our reduction is 25.8 points below the report's");
        let sah = why("bvh-sah needs fewer");
        assert!(sah.starts_with("not fewer than bvh-seed-ordered everywhere: on test 1 bvh-sah makes 2.0 % more (510 against 500); on test 2 both make 20"), "{sah}");
        assert!(sah.ends_with("within 1.0 % of the bound on every test"), "{sah}");
        assert_eq!(why("test 1: bvh-sah makes"), "31.0 points short of the aim");
        assert_eq!(why("every accelerator"), "images differ: test 1 with bvh-sah (3 pixels)");
    }

    #[test]
    fn the_table_labels_whose_counts_at_which_size() {
        let text = table(&[row(1, AccelKind::None, 1000, 0.0)], 64, 64, 1, 2);
        assert!(
            text.contains("Absolute counts are ours at 64x64, the size run, and the report's at its 512x512"),
            "{text}"
        );
        assert!(text.contains("tests 64x64") && text.contains("report 512x512"), "{text}");
    }
}
