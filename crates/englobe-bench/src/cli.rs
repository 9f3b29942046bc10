//! The benchmark's options, shared by the `englobe-bench` binary and `englobe bench`.

use std::path::PathBuf;

use clap::Args;

use crate::adapters::englobe::EnglobeStructure;
use crate::agreement::DEFAULT_MISMATCH_TOLERANCE;
use crate::rays::{DEFAULT_RAY_COUNT, DEFAULT_RESOLUTION, DEFAULT_SEED};
use crate::registry::LibraryKind;
use crate::report::Cell;
use crate::scene::{SceneSpec, ViewSpec};

/// Largest primary image side accepted.
pub const MAX_RESOLUTION: u32 = 4096;
/// Most random (and bounce) rays accepted.
pub const MAX_RAY_COUNT: usize = 1 << 24;
/// Most threads accepted.
pub const MAX_THREADS: usize = 1024;
/// Largest pre-split budget accepted, in percent more references (ten times the triangles).
pub const MAX_PRESPLIT_PERCENT: u32 = 1000;

/// Measure englobe against Intel Embree, obvhs and bvh on the same rays.
#[derive(Args, Clone, Debug)]
pub struct BenchArgs {
    /// Scenes: `[NAME=]PATH[@XxYxZ]`, a mesh file (.obj, .ply, .gltf, .glb), optionally named and
    /// tiled into a grid of copies (`bunny-16=bunny.obj@4x2x2`).
    #[arg(required = true, value_parser = SceneSpec::parse, value_name = "SCENE")]
    pub scenes: Vec<SceneSpec>,
    /// A camera inside a scene for its primary rays, instead of the one that frames the mesh from
    /// outside: `NAME=EX,EY,EZ,DX,DY,DZ,FOV` (eye, direction, field of view in degrees, up +y;
    /// repeatable). The Sponza from inside: `sponza=-10.43876,7.37331,0.00149,1,0,0,60`.
    #[arg(long, value_parser = ViewSpec::parse, value_name = "NAME=EYE,DIR,FOV")]
    pub view: Vec<ViewSpec>,
    /// Thread counts to measure, comma-separated.
    #[arg(long, value_delimiter = ',', default_values_t = [1usize, 2])]
    pub threads: Vec<usize>,
    /// Timed runs per measurement (after one warm-up run); the median is reported.
    #[arg(long, default_value_t = 5)]
    pub reps: usize,
    /// Builds per library (default: as many as --reps); the median is reported.
    #[arg(long)]
    pub build_reps: Option<usize>,
    /// Libraries, comma-separated (default: every one this build has: embree, embree-packet16
    /// with the `embree` feature, englobe, obvhs, bvh).
    #[arg(long, value_delimiter = ',')]
    pub libraries: Vec<LibraryKind>,
    /// englobe's structure (default: the best this build of englobe has).
    #[arg(long, value_parser = EnglobeStructure::parse, value_name = "NAME")]
    pub englobe_accel: Option<EnglobeStructure>,
    /// Pre-split budget of englobe's triangle BVH, in percent more references than triangles,
    /// with no spatial splits (default: the library's cuts, `TriangleBvhOptions::default()`:
    /// spatial splits on a scene of large triangles, else the pre-split; 0 cuts no triangle).
    #[arg(long, value_name = "PERCENT")]
    pub englobe_presplit: Option<u32>,
    /// Cells to measure, comma-separated, or `all` (default: primary-closest, random-closest,
    /// random-any, bounce-closest).
    #[arg(long, value_delimiter = ',')]
    pub cells: Vec<String>,
    /// Side of the square primary image.
    #[arg(long, default_value_t = DEFAULT_RESOLUTION)]
    pub resolution: u32,
    /// Random rays, and bounce rays.
    #[arg(long, default_value_t = DEFAULT_RAY_COUNT)]
    pub rays: usize,
    /// Seed of the random and bounce rays.
    #[arg(long, default_value_t = DEFAULT_SEED)]
    pub seed: u64,
    /// Rays of each set compared with brute force.
    #[arg(long, default_value_t = 10_000)]
    pub check_rays: usize,
    /// Most ray/triangle tests brute force may make per ray set (fewer rays are checked on
    /// larger scenes, never fewer than 100).
    #[arg(long, default_value_t = 2e9)]
    pub check_budget: f64,
    /// Fraction of the checked rays that may disagree with brute force (at least one ray).
    #[arg(long, default_value_t = DEFAULT_MISMATCH_TOLERANCE)]
    pub tolerance: f64,
    /// Skip the agreement checks.
    #[arg(long)]
    pub no_check: bool,
    /// Build Embree's scenes with RTC_SCENE_FLAG_ROBUST.
    #[arg(long)]
    pub embree_robust: bool,
    /// The CSV to write (atomically); its path is the last line printed.
    #[arg(long, short = 'o', default_value = "englobe-bench.csv", value_name = "FILE")]
    pub csv: PathBuf,
    /// No progress lines on standard error.
    #[arg(long, short)]
    pub quiet: bool,
}

impl BenchArgs {
    /// The libraries to run, in table order.
    pub fn library_list(&self) -> Vec<LibraryKind> {
        if self.libraries.is_empty() {
            return LibraryKind::available_kinds();
        }
        LibraryKind::ALL.into_iter().filter(|k| self.libraries.contains(k)).collect()
    }

    /// The cells to measure.
    pub fn cell_list(&self) -> Result<Vec<Cell>, String> {
        if self.cells.is_empty() {
            return Ok(Cell::DEFAULT.to_vec());
        }
        if self.cells.iter().any(|c| c == "all") {
            return Ok(Cell::all());
        }
        let mut cells = self.cells.iter().map(|c| Cell::parse(c)).collect::<Result<Vec<_>, _>>()?;
        cells.sort();
        cells.dedup();
        Ok(cells)
    }

    /// Refuses absurd settings before anything is allocated.
    pub fn validate(&self) -> Result<(), String> {
        if self.threads.is_empty() || self.threads.iter().any(|&t| t == 0 || t > MAX_THREADS) {
            return Err(format!("--threads: every count must be between 1 and {MAX_THREADS}"));
        }
        if self.reps == 0 || self.build_reps == Some(0) {
            return Err("--reps and --build-reps must be at least 1".into());
        }
        if self.resolution == 0 || self.resolution > MAX_RESOLUTION || !self.resolution.is_multiple_of(4) {
            return Err(format!("--resolution must be a multiple of 4 between 4 and {MAX_RESOLUTION}"));
        }
        if self.rays == 0 || self.rays > MAX_RAY_COUNT {
            return Err(format!("--rays must be between 1 and {MAX_RAY_COUNT}"));
        }
        if self.englobe_presplit.is_some_and(|p| p > MAX_PRESPLIT_PERCENT) {
            return Err(format!("--englobe-presplit must be at most {MAX_PRESPLIT_PERCENT} (percent more references)"));
        }
        if !(0.0..=1.0).contains(&self.tolerance) {
            return Err("--tolerance is a fraction between 0 and 1".into());
        }
        if !(self.check_budget >= 0.0) {
            return Err("--check-budget must be a non-negative number of tests".into());
        }
        self.cell_list()?;
        Ok(())
    }
}
