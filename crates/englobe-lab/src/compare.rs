//! The comparison (`englobe compare SCENE`): every structure of `AccelKind::ALL` built for one
//! scene and used to render it: build time, memory, rays per second (and how many times brute force's), and the
//! work per ray (exact tests, nodes visited, box tests); then whether its image is brute force's,
//! bit for bit. A second table gives the quality of every structure: SAH cost (and its ratio to
//! the full-sweep builder's) where it applies, interior nodes, leaves (a grid's cells), depth,
//! references per primitive (more than one where a structure lists a primitive in every cell it
//! overlaps) and the leaves' sizes. `--plot` draws rays per second and exact tests per ray.
//!
//! A structure whose full render would take longer than the time budget (brute force on a large
//! mesh) is measured on a regular sample of the pixels instead: every `n`-th pixel of every
//! `n`-th row, `n` a power of two chosen from a quick probe at a coarse stride. The table says so,
//! and its image is compared with brute force's on the pixels both rendered.
//!
//! Every structure's world is built first and kept, so that the timed renders can take turns, one
//! structure after another, round after round: a busy spell of a shared machine then slows every
//! structure a little rather than one a lot, and the ratios between them hold.

use std::path::Path;

use englobe::AccelKind;
use englobe::accel::LEAF_SIZE_BUCKETS;
use englobe::accel::bvh::{SAH_INTERSECTION_COST, SAH_TRAVERSAL_COST};
use englobe_render::{Film, RenderOutput};
use englobe_scene::Scene;
use serde::Serialize;

use crate::error::LabError;
use crate::measure::{MIN_TIMED_SECONDS, RenderSettings, build, compare_films, render, thread_pool};
use crate::plot::{PlotRow, write_svg};
use crate::report::{bytes, write_json};

/// What to compare, and how.
#[derive(Clone, Debug)]
pub struct CompareOptions {
    /// Image width in pixels (default: the scene's).
    pub width: Option<u32>,
    /// Image height in pixels (default: the scene's).
    pub height: Option<u32>,
    /// Samples per pixel (default: the scene's).
    pub spp: Option<u32>,
    /// Only these accelerators (default: all); brute force (none) always runs, as the reference.
    pub accel: Vec<AccelKind>,
    /// Worker threads (default: all cores).
    pub threads: Option<u32>,
    /// Seconds one render may take before the structure is measured on a sample of the pixels.
    pub budget: f64,
    /// Render every pixel with every structure, however long it takes.
    pub full: bool,
}

impl Default for CompareOptions {
    fn default() -> Self {
        CompareOptions {
            width: None,
            height: None,
            spp: None,
            accel: Vec::new(),
            threads: None,
            budget: 10.0,
            full: false,
        }
    }
}

/// One structure's line.
#[derive(Clone, Debug, Serialize)]
pub struct CompareRow {
    /// The structure's name.
    pub accel: &'static str,
    /// Seconds to build the world (the primitives' boxes and the structure over them).
    pub build_seconds: f64,
    /// Bytes the structure holds.
    pub memory_bytes: usize,
    /// Interior nodes plus leaves.
    pub nodes: usize,
    /// Interior nodes (a kd-tree's split nodes; a grid has none).
    pub interior_nodes: usize,
    /// Leaves (a grid's cells).
    pub leaves: usize,
    /// Depth of the deepest leaf.
    pub depth: usize,
    /// Primitive references held by the leaves (cells).
    pub prim_refs: usize,
    /// References per primitive of the structure.
    pub refs_per_prim: f64,
    /// SAH cost, with the constants of the report's `sah_constants`.
    pub sah_cost: Option<f32>,
    /// SAH cost over bvh-sweep's, when both were built.
    pub sah_vs_sweep: Option<f64>,
    /// Leaves of 1, 2, ..., 8 primitives, then of more.
    pub leaf_sizes: [usize; LEAF_SIZE_BUCKETS],
    /// Rays of the timed render (all rays of the pixels rendered).
    pub rays: u64,
    /// Seconds of the timed render (counting off): the best of `timed_runs` renders.
    pub seconds: f64,
    /// Renders timed: as many as fit in two seconds, at most fifty, the structures taking turns.
    pub timed_runs: u32,
    /// Rays of the timed render over its time.
    pub rays_per_second: f64,
    /// Rays per second over brute force's (both measured in this run).
    pub speedup_vs_none: f64,
    /// Exact primitive tests per ray, counted in a second render.
    pub exact_tests_per_ray: f64,
    /// Nodes visited per ray.
    pub nodes_visited_per_ray: f64,
    /// Box tests per ray.
    pub box_tests_per_ray: f64,
    /// 1 when every pixel was rendered; `n` when only every `n`-th pixel of every `n`-th row was.
    pub pixel_stride: u32,
    /// Whether only a sample of the pixels was rendered (`pixel_stride` over 1).
    pub sampled: bool,
    /// Same image as brute force on every pixel both rendered.
    pub image_equal: bool,
    /// Pixels compared with brute force's image.
    pub compared_pixels: usize,
    /// Pixels of those that differ, bit for bit.
    pub differing_pixels: usize,
}

/// The comparison's results, as `--json` writes them.
#[derive(Clone, Debug, Serialize)]
pub struct Comparison {
    /// The scene's file, or `default`.
    pub scene: String,
    /// Primitives in the structures.
    pub primitives: usize,
    /// Image width.
    pub width: u32,
    /// Image height.
    pub height: u32,
    /// Samples per pixel.
    pub samples: u32,
    /// Worker threads.
    pub threads: usize,
    /// The time budget of one render, in seconds.
    pub budget_seconds: f64,
    /// The constants of the SAH costs.
    pub sah_constants: SahConstants,
    /// One row per structure, brute force first.
    pub rows: Vec<CompareRow>,
}

/// The constants the SAH costs are computed with (see `englobe::accel::bvh::stats`).
#[derive(Clone, Copy, Debug, Serialize)]
pub struct SahConstants {
    /// Cost of visiting an interior node.
    pub traversal: f32,
    /// Cost of one exact primitive test.
    pub intersection: f32,
}

/// Most timed renders per structure. Renders of the default scenes take a few hundredths of a
/// second, and on a shared machine the best of many is the one a busy neighbour left alone; the
/// two seconds of [`MIN_TIMED_SECONDS`] still bound the time a slower structure takes.
const MAX_TURNS: u32 = 50;

/// Coarsest stride of the probe render.
const PROBE_STRIDE: u32 = 32;
/// Fewest pixels a probe renders (the stride is refined until it has them).
const PROBE_PIXELS: u64 = 256;

/// Builds every structure of `options` for `scene` (called `scene_name` in the report) and renders
/// with it; `progress` is told what is being built and rendered.
pub fn run_compare(
    scene: &Scene,
    scene_name: &str,
    options: &CompareOptions,
    progress: &mut dyn FnMut(&str),
) -> Result<Comparison, LabError> {
    // A noise threshold decides the samples of whole blocks of pixels, which a sample of the
    // pixels (a slow structure's timing) cannot honour: structures are compared with the scene's
    // samples in every pixel.
    let uniform;
    let scene = if scene.image.noise_threshold > 0.0 {
        let mut s = scene.clone();
        s.image.noise_threshold = 0.0;
        uniform = s;
        &uniform
    } else {
        scene
    };
    let width = options.width.unwrap_or(scene.image.width);
    let height = options.height.unwrap_or(scene.image.height);
    let samples = options.spp.unwrap_or(scene.image.samples);
    let settings = RenderSettings { width, height, samples, count_work: false, stride: 1 };
    let mut kinds: Vec<AccelKind> =
        AccelKind::ALL.iter().copied().filter(|k| options.accel.is_empty() || options.accel.contains(k)).collect();
    if !kinds.contains(&AccelKind::None) {
        kinds.insert(0, AccelKind::None);
    }
    let pool = thread_pool(options.threads)?;
    let mut measured: Vec<Measured> = Vec::new();
    let mut reference: Option<(Film, u32)> = None;
    let mut primitives = 0;
    for kind in kinds {
        progress(&format!("{kind}: building..."));
        let (world, build_seconds) = build(scene, kind)?;
        primitives = world.primitive_count();
        let stride =
            if options.full { 1 } else { pool.install(|| choose_stride(scene, &world, settings, options.budget))? };
        let sample = if stride > 1 { format!(" 1 pixel in {stride}x{stride}") } else { String::new() };
        progress(&format!("{kind}: rendering{sample}..."));
        let settings = RenderSettings { stride, ..settings };
        let timed = pool.install(|| render(scene, &world, settings))?;
        let counted = pool.install(|| render(scene, &world, RenderSettings { count_work: true, ..settings }))?;
        let (film_ref, stride_ref) = reference.get_or_insert_with(|| (timed.film.clone(), stride));
        let (compared, differing) = compare_films(film_ref, *stride_ref, &timed.film, stride);
        let timing = Timing { seconds: timed.seconds, spent: timed.seconds, runs: 1, rays: timed.stats.total().rays };
        let stats = world.stats();
        let mut r = row(kind, build_seconds, &stats, &counted, stride, compared, differing);
        r.refs_per_prim = if primitives == 0 { 0.0 } else { stats.prim_refs as f64 / primitives as f64 };
        measured.push(Measured { world, settings, timing, row: r });
    }
    // Short renders are timed again and the best time kept, as `experiment` does: on a busy
    // machine one render of a fraction of a second says little. The structures take turns, round
    // after round, so that a busy spell of the machine slows them all rather than one.
    progress("timing...");
    while measured.iter().any(|m| m.timing.wants_another()) {
        for m in measured.iter_mut().filter(|m| m.timing.wants_another()) {
            let seconds = pool.install(|| render(scene, &m.world, m.settings))?.seconds;
            m.timing.add(seconds);
        }
    }
    let mut rows: Vec<CompareRow> = measured.into_iter().map(|m| m.timing.fill(m.row)).collect();
    relate_rows(&mut rows);
    Ok(Comparison {
        scene: scene_name.to_owned(),
        primitives,
        width,
        height,
        samples,
        threads: pool.current_num_threads(),
        budget_seconds: options.budget,
        sah_constants: SahConstants { traversal: SAH_TRAVERSAL_COST, intersection: SAH_INTERSECTION_COST },
        rows,
    })
}

impl Comparison {
    /// The table of speed and work, one structure a line.
    pub fn table(&self) -> String {
        table(&self.scene, self.primitives, self.width, self.height, self.samples, self.threads, &self.rows)
    }

    /// The table of quality (SAH cost, shape, leaf sizes) of every structure but brute force.
    pub fn quality_table(&self) -> String {
        quality_table(&self.rows)
    }

    /// Whether every structure drew brute force's image on every pixel both rendered.
    pub fn images_equal(&self) -> bool {
        self.rows.iter().all(|r| r.image_equal)
    }

    /// Writes the results as JSON to `path`, atomically.
    pub fn write_json(&self, path: &Path) -> Result<(), LabError> {
        write_json(path, self)
    }

    /// Draws rays per second and exact tests per ray of every structure into the SVG file `path`.
    pub fn write_plot(&self, path: &Path) -> Result<(), LabError> {
        let (rows, subtitle) = self.plot();
        write_svg(path, &self.scene, &subtitle, &rows)
    }

    /// What the plot draws: a row per structure, and the subtitle that says what was measured.
    pub(crate) fn plot(&self) -> (Vec<PlotRow>, String) {
        let rows = self
            .rows
            .iter()
            .map(|r| PlotRow {
                name: r.accel.to_owned(),
                rays_per_second: r.rays_per_second,
                exact_tests_per_ray: r.exact_tests_per_ray,
            })
            .collect();
        let (primitives, width, height, samples, threads) =
            (self.primitives, self.width, self.height, self.samples, self.threads);
        (rows, format!("{primitives} primitives, {width}x{height}, {samples} sample(s) per pixel, {threads} threads"))
    }
}

/// The pixel stride that keeps one render within `budget` seconds: 1 if the full image fits,
/// otherwise the smallest power of two whose sample fits, estimated from a probe render at a
/// coarse stride.
fn choose_stride(
    scene: &Scene,
    world: &englobe::World,
    settings: RenderSettings,
    budget: f64,
) -> Result<u32, LabError> {
    let sampled = |stride: u32| (settings.width.div_ceil(stride) as u64) * (settings.height.div_ceil(stride) as u64);
    let mut probe = PROBE_STRIDE;
    while probe > 1 && sampled(probe) < PROBE_PIXELS {
        probe /= 2;
    }
    let out = render(scene, world, RenderSettings { stride: probe, ..settings })?;
    let per_pixel = out.seconds / sampled(probe) as f64;
    let mut stride = 1;
    while stride < probe && per_pixel * sampled(stride) as f64 > budget {
        stride *= 2;
    }
    Ok(stride)
}

/// One structure under comparison: its world, how it is rendered, its timing so far and its row.
struct Measured {
    world: englobe::World,
    settings: RenderSettings,
    timing: Timing,
    row: CompareRow,
}

/// The timed renders of one structure: the best time, the time spent, how many renders, and the
/// rays of one render.
#[derive(Clone, Copy, Debug)]
struct Timing {
    seconds: f64,
    spent: f64,
    runs: u32,
    rays: u64,
}

impl Timing {
    /// Whether another render should be timed: fewer than [`MAX_TURNS`] in under
    /// [`MIN_TIMED_SECONDS`] so far.
    fn wants_another(&self) -> bool {
        self.spent < MIN_TIMED_SECONDS && self.runs < MAX_TURNS
    }

    fn add(&mut self, seconds: f64) {
        (self.seconds, self.spent, self.runs) = (self.seconds.min(seconds), self.spent + seconds, self.runs + 1);
    }

    /// `row` with this timing's figures.
    fn fill(self, row: CompareRow) -> CompareRow {
        CompareRow {
            rays: self.rays,
            seconds: self.seconds,
            timed_runs: self.runs,
            rays_per_second: if self.seconds > 0.0 { self.rays as f64 / self.seconds } else { 0.0 },
            ..row
        }
    }
}

fn row(
    kind: AccelKind,
    build_seconds: f64,
    s: &englobe::accel::StructureStats,
    counted: &RenderOutput,
    stride: u32,
    compared: usize,
    differing: usize,
) -> CompareRow {
    let work = counted.stats.total();
    let per_ray = |n: u64| if work.rays == 0 { 0.0 } else { n as f64 / work.rays as f64 };
    CompareRow {
        accel: kind.name(),
        build_seconds,
        memory_bytes: s.memory_bytes,
        nodes: s.nodes + s.leaves,
        interior_nodes: s.nodes,
        leaves: s.leaves,
        depth: s.depth,
        prim_refs: s.prim_refs,
        refs_per_prim: 0.0,
        sah_cost: s.sah_cost,
        sah_vs_sweep: None,
        leaf_sizes: s.leaf_sizes,
        rays: 0,
        seconds: 0.0,
        timed_runs: 0,
        rays_per_second: 0.0,
        speedup_vs_none: 0.0,
        exact_tests_per_ray: per_ray(work.exact_tests),
        nodes_visited_per_ray: per_ray(work.nodes_visited),
        box_tests_per_ray: per_ray(work.box_tests),
        pixel_stride: stride,
        sampled: stride > 1,
        image_equal: differing == 0,
        compared_pixels: compared,
        differing_pixels: differing,
    }
}

/// Fills in what each row says relative to the others: speed over brute force's, SAH cost over
/// bvh-sweep's.
fn relate_rows(rows: &mut [CompareRow]) {
    let none = rows.iter().find(|r| r.accel == AccelKind::None.name()).map(|r| r.rays_per_second);
    let sweep = rows.iter().find(|r| r.accel == AccelKind::BvhSweep.name()).and_then(|r| r.sah_cost);
    for r in rows.iter_mut() {
        r.speedup_vs_none = match none {
            Some(n) if n > 0.0 => r.rays_per_second / n,
            _ => 0.0,
        };
        r.sah_vs_sweep = match (r.sah_cost, sweep) {
            (Some(c), Some(s)) if s > 0.0 => Some(c as f64 / s as f64),
            _ => None,
        };
    }
}

fn table(scene: &str, primitives: usize, w: u32, h: u32, spp: u32, threads: usize, rows: &[CompareRow]) -> String {
    let mut out = format!(
        "{scene}: {primitives} primitives in the structure, {w}x{h}, {spp} sample(s) per pixel, {threads} threads{}\n\n",
        if cfg!(debug_assertions) { ", debug build (times are not representative)" } else { "" },
    );
    out += &format!(
        "{:<18} {:>10} {:>10} {:>9} {:>9} {:>10} {:>10} {:>10} {:>8}  {}\n",
        "accelerator",
        "build ms",
        "memory",
        "Mrays/s",
        "x none",
        "tests/ray",
        "nodes/ray",
        "boxes/ray",
        "pixels",
        "image"
    );
    out += &format!("{}\n", "-".repeat(112));
    for r in rows {
        let pixels = if r.sampled { format!("1/{}", r.pixel_stride * r.pixel_stride) } else { "all".to_owned() };
        let image = match (r.accel == AccelKind::None.name(), r.image_equal) {
            (true, _) => "reference".to_owned(),
            (false, true) => "= none".to_owned(),
            (false, false) => format!("{} of {} pixels differ", r.differing_pixels, r.compared_pixels),
        };
        out += &format!(
            "{:<18} {:>10.2} {:>10} {:>9.3} {:>9.1} {:>10.2} {:>10.2} {:>10.2} {:>8}  {}\n",
            r.accel,
            r.build_seconds * 1e3,
            bytes(r.memory_bytes),
            r.rays_per_second / 1e6,
            r.speedup_vs_none,
            r.exact_tests_per_ray,
            r.nodes_visited_per_ray,
            r.box_tests_per_ray,
            pixels,
            image
        );
    }
    out += &format!(
        "\nMrays/s: the rays of one render over the best time of up to {MAX_TURNS} renders (as many as fit in \
         {MIN_TIMED_SECONDS} s), the structures taking turns; x none: that speed over brute force's.\n"
    );
    if rows.iter().any(|r| r.sampled) {
        out += "pixels 1/N: too slow for the time budget (--budget), so timed and counted on a regular sample \
                of 1 pixel in N (--full renders every pixel); images are compared on the pixels both rendered.\n";
    }
    out
}

/// The shape of every structure but brute force, and its SAH cost where it has one.
fn quality_table(rows: &[CompareRow]) -> String {
    let shaped: Vec<&CompareRow> = rows.iter().filter(|r| r.accel != AccelKind::None.name()).collect();
    if shaped.is_empty() {
        return String::new();
    }
    let mut out = format!(
        "\nQuality: SAH cost = expected cost of a ray that hits the root box, {SAH_TRAVERSAL_COST} per interior node \
         and {SAH_INTERSECTION_COST} per primitive of a leaf, each node weighted by its area over the root's (a \
         kd-tree's nodes are cells; a grid has none). A grid's leaves are its cells; refs/prim: references per \
         primitive; leaf sizes count non-empty leaves.\n\n"
    );
    out += &format!(
        "{:<18} {:>10} {:>9} {:>9} {:>9} {:>6} {:>9}  {:<44} {:>6}\n",
        "accelerator",
        "SAH cost",
        "vs sweep",
        "interior",
        "leaves",
        "depth",
        "refs/prim",
        "leaves of 1 2 3 4 5 6 7 8 9+ primitives",
        "mean"
    );
    out += &format!("{}\n", "-".repeat(132));
    for r in shaped {
        let sah = r.sah_cost.map_or("-".to_owned(), |c| format!("{c:.3}"));
        let vs_sweep = r.sah_vs_sweep.map_or("-".to_owned(), |v| format!("{v:.3}"));
        let sizes = r.leaf_sizes.iter().map(|n| n.to_string()).collect::<Vec<_>>().join(" ");
        let filled: usize = r.leaf_sizes.iter().sum();
        let mean = if filled == 0 { 0.0 } else { r.prim_refs as f64 / filled as f64 };
        out += &format!(
            "{:<18} {:>10} {:>9} {:>9} {:>9} {:>6} {:>9.2}  {:<44} {:>6.2}\n",
            r.accel, sah, vs_sweep, r.interior_nodes, r.leaves, r.depth, r.refs_per_prim, sizes, mean
        );
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_noise_threshold_is_compared_with_every_sample_even_on_a_sample_of_the_pixels() {
        let mut scene = englobe_scene::parse_scene(englobe_render::DEFAULT_SCENE, "default.toml".as_ref()).unwrap();
        scene.image.noise_threshold = 0.05;
        scene.image.integrator = englobe_scene::IntegratorKind::Path;
        // A budget of nothing: every structure but the fastest is timed on a sample of the pixels.
        let options = CompareOptions {
            width: Some(64),
            height: Some(48),
            spp: Some(4),
            accel: vec![AccelKind::BvhSah],
            budget: 0.0,
            ..CompareOptions::default()
        };
        let c = run_compare(&scene, "default", &options, &mut |_| {}).unwrap();
        assert!(c.rows.iter().any(|r| r.sampled), "the probe chose a stride");
        assert!(c.images_equal());
        assert_eq!(c.samples, 4);
    }
}
