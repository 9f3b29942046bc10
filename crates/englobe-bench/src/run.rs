//! One benchmark run: every scene file is read first, so that a bad one stops the run before
//! anything is measured; then for each scene, the ray sets are generated once, and for each
//! thread count and library, the library is built (timed), every cell is traced (timed) and its
//! answers are checked against brute force. A table is printed per scene and thread count; the
//! CSV is rewritten (atomically) after every measurement, so that a crash or an interrupt keeps
//! everything measured until then; its path is printed last.

use std::collections::BTreeMap;
use std::io::Write as _;
use std::process::ExitCode;

use anyhow::{Context, anyhow, bail};
use rayon::prelude::*;

use crate::adapters::englobe::{EnglobeLibrary, EnglobeStructure};
use crate::agreement::{self, Mismatches, Reference};
use crate::cli::BenchArgs;
use crate::library::{Library, RayResult};
use crate::measure::{self, Answers, CHUNK};
use crate::rays::{self, RayParams, RaySetKind, RaySets};
use crate::registry::{BuildSettings, LibraryKind, build_library};
use crate::report::{self, Cell};
use crate::results::{self, Measurement};
use crate::scene::BenchScene;

/// Runs the benchmark; the exit code is a failure when a library disagreed with brute force
/// beyond the tolerance (the CSV is written all the same).
pub fn run(args: &BenchArgs) -> anyhow::Result<ExitCode> {
    args.validate().map_err(|e| anyhow!(e))?;
    let cells = args.cell_list().map_err(|e| anyhow!(e))?;
    let libraries = args.library_list();
    if libraries.is_empty() {
        bail!("no library to measure");
    }
    let mut englobe = args.englobe_accel.unwrap_or_else(EnglobeStructure::best);
    if let Some(percent) = args.englobe_presplit {
        englobe = englobe.with_presplit(percent).map_err(|e| anyhow!(e))?;
    }
    let max_threads = *args.threads.iter().max().expect("validated: at least one thread count");
    let progress = |msg: String| {
        if !args.quiet {
            eprintln!("{msg}");
        }
    };
    // Every file read before anything is measured: a bad file at the end of the list must not
    // cost the measurements before it. (Tiled scenes are checked untiled: tiling cannot fail.)
    for spec in &args.scenes {
        BenchScene::load(&spec.name, &spec.path, None)
            .with_context(|| format!("scene `{}` refused before measuring anything", spec.name))?;
    }
    if let Some(v) = args.view.iter().find(|v| !args.scenes.iter().any(|s| s.name == v.scene)) {
        bail!("--view {}=...: no scene of that name", v.scene);
    }
    println!("englobe-bench on {}", report::machine_description());
    println!("englobe structure: {englobe}; seed {}", args.seed);

    let mut all = Vec::new();
    let mut failures = Vec::new();
    for spec in &args.scenes {
        let mut scene = BenchScene::load(&spec.name, &spec.path, spec.tiling)?;
        scene.view = args.view.iter().rev().find(|v| v.scene == scene.name).map(|v| v.view);
        progress(format!("{}: {} triangles; generating rays", scene.name, scene.triangle_count()));
        let params = RayParams { resolution: args.resolution, count: args.rays, seed: args.seed };
        let sets = generate_rays(&scene, params, max_threads)?;
        let references = if args.no_check {
            BTreeMap::new()
        } else {
            progress(format!("{}: brute force on the check samples", scene.name));
            references(&scene, &sets, &cells, args, max_threads)?
        };
        let sampled = |kind: RaySetKind| {
            references.get(&kind).map_or(String::new(), |r| {
                let hits = r.closest.iter().filter(|h| h.is_hit()).count();
                format!(
                    ", {} {:.1} % (of {} checked)",
                    kind.name(),
                    100.0 * hits as f64 / r.closest.len() as f64,
                    r.closest.len()
                )
            })
        };
        println!(
            "\n{}: {} triangles; rays hitting: primary {:.1} %{}{}",
            scene.name,
            scene.triangle_count(),
            100.0 * sets.primary_hit_fraction,
            sampled(RaySetKind::Random),
            sampled(RaySetKind::Bounce)
        );
        for &threads in &args.threads {
            let pool = measure::thread_pool(threads)?;
            let settings = BuildSettings { threads, englobe, embree_robust: args.embree_robust };
            let first = all.len();
            for &kind in &libraries {
                progress(format!("{}: {kind} on {threads} thread(s): building", scene.name));
                let build_reps = args.build_reps.unwrap_or(args.reps);
                let (library, build) =
                    measure::time_build(&pool, build_reps, || build_library(kind, &scene, &settings))?;
                for &cell in &cells {
                    progress(format!("{}: {kind} on {threads} thread(s): {}", scene.name, cell.name()));
                    let (m, mismatches) = measure_cell(&pool, library.as_ref(), &scene, &sets, cell, &references, args);
                    if mismatches.checked > 0 && !mismatches.acceptable(args.tolerance) {
                        failures.push(format!(
                            "{}: {kind} on {threads} thread(s), {}: {} of {} rays disagree with brute force \
                             ({} hit/miss, {} distance)",
                            scene.name,
                            cell.name(),
                            mismatches.total(),
                            mismatches.checked,
                            mismatches.hit_miss,
                            mismatches.distance
                        ));
                    }
                    all.push(Measurement {
                        library: kind,
                        threads,
                        build_ms: build.ms,
                        build_resident_bytes: build.resident_bytes,
                        ..m
                    });
                    results::fill_ratios(&mut all);
                    results::write_atomically(&args.csv, &results::to_csv(&all))?;
                }
            }
            results::fill_ratios(&mut all);
            print!("{}", report::table(&all[first..], &cells));
            std::io::stdout().flush()?;
        }
    }
    results::fill_ratios(&mut all);
    results::write_atomically(&args.csv, &results::to_csv(&all))?;
    let code = if failures.is_empty() {
        println!("\nagreement with brute force: every library within tolerance");
        ExitCode::SUCCESS
    } else {
        println!("\nagreement with brute force FAILED (tolerance {} of the checked rays):", args.tolerance);
        for f in &failures {
            println!("  {f}");
        }
        ExitCode::FAILURE
    };
    println!("{}", args.csv.display());
    Ok(code)
}

/// The three ray sets; the bounce rays start from the primary hits found with englobe's best
/// structure (every englobe structure gives brute force's answers exactly).
pub fn generate_rays(scene: &BenchScene, params: RayParams, threads: usize) -> anyhow::Result<RaySets> {
    let primary = rays::primary_rays(scene, params.resolution);
    let random = rays::random_rays(scene, params.count, params.seed);
    let pool = measure::thread_pool(threads)?;
    let hits = pool.install(|| -> anyhow::Result<Vec<RayResult>> {
        let englobe = EnglobeLibrary::build(scene, EnglobeStructure::best())?;
        let mut hits = vec![RayResult::MISS; primary.len()];
        primary
            .par_chunks(CHUNK)
            .zip(hits.par_chunks_mut(CHUNK))
            .for_each(|(rays, out)| englobe.closest_hits(rays, out));
        Ok(hits)
    })?;
    let bounce = rays::bounce_rays(scene, &primary, &hits, params.count, params.seed);
    if bounce.is_empty() {
        bail!("{}: no primary ray hits the mesh, so there are no bounce rays", scene.name);
    }
    let primary_hit_fraction = hits.iter().filter(|h| h.is_hit()).count() as f64 / hits.len() as f64;
    Ok(RaySets { primary, random, bounce, primary_hit_fraction })
}

/// Brute force's answers on the samples of the sets the cells use.
fn references(
    scene: &BenchScene,
    sets: &RaySets,
    cells: &[Cell],
    args: &BenchArgs,
    threads: usize,
) -> anyhow::Result<BTreeMap<RaySetKind, Reference>> {
    let pool = measure::thread_pool(threads)?;
    let mut out = BTreeMap::new();
    for kind in RaySetKind::ALL.into_iter().filter(|k| cells.iter().any(|c| c.rays == *k)) {
        let rays = sets.get(kind);
        let n = agreement::sample_size(rays.len(), scene.triangle_count(), args.check_rays, args.check_budget);
        let reference = pool.install(|| agreement::reference(scene, rays, n)).context("brute force")?;
        out.insert(kind, reference);
    }
    Ok(out)
}

/// Times one cell and checks its answers (the measurement's library, threads and build time are
/// the caller's to fill in).
fn measure_cell(
    pool: &rayon::ThreadPool,
    library: &dyn Library,
    scene: &BenchScene,
    sets: &RaySets,
    cell: Cell,
    references: &BTreeMap<RaySetKind, Reference>,
    args: &BenchArgs,
) -> (Measurement, Mismatches) {
    let rays = sets.get(cell.rays);
    let mut answers = Answers::new(cell.query, rays.len());
    let timing = measure::time_query(pool, library, rays, &mut answers, args.reps);
    let mismatches = references.get(&cell.rays).map(|r| match &answers {
        Answers::Closest(out) => agreement::check_closest(r, out),
        Answers::Any(out) => agreement::check_any(r, out),
    });
    let mismatches = mismatches.unwrap_or_default();
    let m = Measurement {
        scene: scene.name.clone(),
        triangles: scene.triangle_count(),
        library: LibraryKind::Englobe,
        structure: library.structure(),
        rays: cell.rays,
        query: cell.query,
        threads: 1,
        ray_count: rays.len(),
        reps: args.reps,
        seconds: timing.median(),
        build_ms: 0.0,
        build_resident_bytes: None,
        checked: mismatches.checked,
        mismatches: mismatches.total(),
        ratio_to_embree: None,
        ratio_to_obvhs: None,
        seed: args.seed,
    };
    (m, mismatches)
}
