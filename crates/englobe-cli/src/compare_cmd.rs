//! `englobe compare SCENE`: every structure of `AccelKind::ALL` built for one scene and used to
//! render it: build time, memory, rays per second (and how many times brute force's), and the
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

use std::path::PathBuf;
use std::process::ExitCode;

use clap::Args;
use englobe::AccelKind;
use englobe::accel::LEAF_SIZE_BUCKETS;
use englobe::accel::bvh::{SAH_INTERSECTION_COST, SAH_TRAVERSAL_COST};
use englobe_render::{Film, RenderOutput};
use englobe_scene::Scene;
use serde::Serialize;

use crate::measure::{MAX_TIMED_RUNS, MIN_TIMED_SECONDS, RenderSettings, build, compare_films, render, thread_pool};
use crate::plot::{PlotRow, write_svg};
use crate::render_cmd::{parse_accel, read_scene};
use crate::report::{bytes, write_json};

#[derive(Args)]
pub struct CompareArgs {
    /// Scene file (TOML, see docs/scene-format.md); the embedded default scene if omitted.
    scene: Option<PathBuf>,
    /// Image width in pixels (overrides the scene).
    #[arg(long)]
    width: Option<u32>,
    /// Image height in pixels (overrides the scene).
    #[arg(long)]
    height: Option<u32>,
    /// Samples per pixel (overrides the scene).
    #[arg(long)]
    spp: Option<u32>,
    /// Only these accelerators, comma-separated (default: all); brute force (none) always runs, as
    /// the reference.
    #[arg(long, value_delimiter = ',', value_parser = parse_accel)]
    accel: Vec<AccelKind>,
    /// Worker threads (default: all cores).
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..=4096))]
    threads: Option<u32>,
    /// Seconds one render may take before the structure is measured on a sample of the pixels.
    #[arg(long, default_value_t = 10.0, value_name = "SECONDS")]
    budget: f64,
    /// Render every pixel with every structure, however long it takes.
    #[arg(long)]
    full: bool,
    /// Also write the table as JSON to this file.
    #[arg(long, value_name = "FILE")]
    json: Option<PathBuf>,
    /// Also draw rays per second and exact tests per ray of every structure into this SVG file.
    #[arg(long, value_name = "FILE.svg")]
    plot: Option<PathBuf>,
    /// No progress lines on standard error.
    #[arg(short, long)]
    quiet: bool,
}

/// One structure's line.
#[derive(Clone, Debug, Serialize)]
struct Row {
    accel: &'static str,
    build_seconds: f64,
    memory_bytes: usize,
    /// Interior nodes plus leaves.
    nodes: usize,
    interior_nodes: usize,
    leaves: usize,
    depth: usize,
    /// Primitive references held by the leaves (cells).
    prim_refs: usize,
    /// References per primitive of the structure.
    refs_per_prim: f64,
    /// SAH cost, with the constants of the report's `sah_constants`.
    sah_cost: Option<f32>,
    /// SAH cost over bvh-sweep's, when both were built.
    sah_vs_sweep: Option<f64>,
    /// Leaves of 1, 2, ..., 8 primitives, then of more.
    leaf_sizes: [usize; LEAF_SIZE_BUCKETS],
    /// Rays of the timed render (all rays of the pixels rendered).
    rays: u64,
    /// Seconds of the timed render (counting off): the best of `timed_runs` renders.
    seconds: f64,
    /// Renders timed: as many as fit in two seconds, at most ten.
    timed_runs: u32,
    rays_per_second: f64,
    /// Rays per second over brute force's (both measured in this run).
    speedup_vs_none: f64,
    exact_tests_per_ray: f64,
    nodes_visited_per_ray: f64,
    box_tests_per_ray: f64,
    /// 1 when every pixel was rendered; `n` when only every `n`-th pixel of every `n`-th row was.
    pixel_stride: u32,
    sampled: bool,
    /// Same image as brute force on every pixel both rendered.
    image_equal: bool,
    compared_pixels: usize,
    differing_pixels: usize,
}

#[derive(Serialize)]
struct CompareReport<'a> {
    scene: &'a str,
    primitives: usize,
    width: u32,
    height: u32,
    samples: u32,
    threads: usize,
    budget_seconds: f64,
    sah_constants: SahConstants,
    rows: Vec<Row>,
}

/// The constants the SAH costs are computed with (see `englobe::accel::bvh::stats`).
#[derive(Serialize)]
struct SahConstants {
    /// Cost of visiting an interior node.
    traversal: f32,
    /// Cost of one exact primitive test.
    intersection: f32,
}

/// Coarsest stride of the probe render.
const PROBE_STRIDE: u32 = 32;
/// Fewest pixels a probe renders (the stride is refined until it has them).
const PROBE_PIXELS: u64 = 256;

pub fn run(args: CompareArgs) -> anyhow::Result<ExitCode> {
    let (scene, scene_name) = read_scene(args.scene.as_ref())?;
    let width = args.width.unwrap_or(scene.image.width);
    let height = args.height.unwrap_or(scene.image.height);
    let samples = args.spp.unwrap_or(scene.image.samples);
    let settings = RenderSettings { width, height, samples, count_work: false, stride: 1 };
    let mut kinds: Vec<AccelKind> =
        AccelKind::ALL.iter().copied().filter(|k| args.accel.is_empty() || args.accel.contains(k)).collect();
    if !kinds.contains(&AccelKind::None) {
        kinds.insert(0, AccelKind::None);
    }
    let pool = thread_pool(args.threads)?;
    let mut rows = Vec::new();
    let mut reference: Option<(Film, u32)> = None;
    let mut primitives = 0;
    for kind in kinds {
        if !args.quiet {
            eprintln!("{kind}: building...");
        }
        let (world, build_seconds) = build(&scene, kind)?;
        primitives = world.primitive_count();
        let stride = if args.full { 1 } else { pool.install(|| choose_stride(&scene, &world, settings, args.budget))? };
        if !args.quiet {
            let sample = if stride > 1 { format!(" 1 pixel in {stride}x{stride}") } else { String::new() };
            eprintln!("{kind}: rendering{sample}...");
        }
        let timed = pool.install(|| render(&scene, &world, RenderSettings { stride, ..settings }))?;
        // Short renders are timed again and the best time kept, as `experiment` does: on a busy
        // machine one render of a fraction of a second says little.
        let (mut seconds, mut spent, mut timed_runs) = (timed.seconds, timed.seconds, 1);
        while spent < MIN_TIMED_SECONDS && timed_runs < MAX_TIMED_RUNS {
            let again = pool.install(|| render(&scene, &world, RenderSettings { stride, ..settings }))?.seconds;
            (seconds, spent, timed_runs) = (seconds.min(again), spent + again, timed_runs + 1);
        }
        let counted =
            pool.install(|| render(&scene, &world, RenderSettings { stride, count_work: true, ..settings }))?;
        let (film_ref, stride_ref) = reference.get_or_insert_with(|| (timed.film.clone(), stride));
        let (compared, differing) = compare_films(film_ref, *stride_ref, &timed.film, stride);
        let timing = Timing { seconds, runs: timed_runs, rays: timed.stats.total().rays };
        let stats = world.stats();
        let mut r = row(kind, build_seconds, &stats, timing, &counted, stride, compared, differing);
        r.refs_per_prim = if primitives == 0 { 0.0 } else { stats.prim_refs as f64 / primitives as f64 };
        rows.push(r);
    }
    relate_rows(&mut rows);
    let threads = pool.current_num_threads();
    print!("{}", table(&scene_name, primitives, width, height, samples, threads, &rows));
    print!("{}", quality_table(&rows));
    if let Some(path) = &args.json {
        let report = CompareReport {
            scene: &scene_name,
            primitives,
            width,
            height,
            samples,
            threads,
            budget_seconds: args.budget,
            sah_constants: SahConstants { traversal: SAH_TRAVERSAL_COST, intersection: SAH_INTERSECTION_COST },
            rows: rows.clone(),
        };
        write_json(path, &report)?;
    }
    if let Some(path) = &args.plot {
        let plotted: Vec<PlotRow> = rows
            .iter()
            .map(|r| PlotRow {
                name: r.accel.to_owned(),
                rays_per_second: r.rays_per_second,
                exact_tests_per_ray: r.exact_tests_per_ray,
            })
            .collect();
        let subtitle =
            format!("{primitives} primitives, {width}x{height}, {samples} sample(s) per pixel, {threads} threads");
        write_svg(path, &scene_name, &subtitle, &plotted)?;
    }
    if rows.iter().any(|r| !r.image_equal) {
        eprintln!("error: some structures drew a different image than brute force");
        return Ok(ExitCode::from(2));
    }
    Ok(ExitCode::SUCCESS)
}

/// The pixel stride that keeps one render within `budget` seconds: 1 if the full image fits,
/// otherwise the smallest power of two whose sample fits, estimated from a probe render at a
/// coarse stride.
fn choose_stride(scene: &Scene, world: &englobe::World, settings: RenderSettings, budget: f64) -> anyhow::Result<u32> {
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

/// The timed renders of one structure: the best time, of how many, and the rays of one render.
#[derive(Clone, Copy, Debug)]
struct Timing {
    seconds: f64,
    runs: u32,
    rays: u64,
}

#[allow(clippy::too_many_arguments)]
fn row(
    kind: AccelKind,
    build_seconds: f64,
    s: &englobe::accel::StructureStats,
    timed: Timing,
    counted: &RenderOutput,
    stride: u32,
    compared: usize,
    differing: usize,
) -> Row {
    let work = counted.stats.total();
    let per_ray = |n: u64| if work.rays == 0 { 0.0 } else { n as f64 / work.rays as f64 };
    Row {
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
        rays: timed.rays,
        seconds: timed.seconds,
        timed_runs: timed.runs,
        rays_per_second: if timed.seconds > 0.0 { timed.rays as f64 / timed.seconds } else { 0.0 },
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
fn relate_rows(rows: &mut [Row]) {
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

fn table(scene: &str, primitives: usize, w: u32, h: u32, spp: u32, threads: usize, rows: &[Row]) -> String {
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
        "\nMrays/s: the rays of one render over the best time of up to {MAX_TIMED_RUNS} renders (as many as fit in \
         {MIN_TIMED_SECONDS} s); x none: that speed over brute force's.\n"
    );
    if rows.iter().any(|r| r.sampled) {
        out += "pixels 1/N: too slow for the time budget (--budget), so timed and counted on a regular sample \
                of 1 pixel in N (--full renders every pixel); images are compared on the pixels both rendered.\n";
    }
    out
}

/// The shape of every structure but brute force, and its SAH cost where it has one.
fn quality_table(rows: &[Row]) -> String {
    let shaped: Vec<&Row> = rows.iter().filter(|r| r.accel != AccelKind::None.name()).collect();
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
