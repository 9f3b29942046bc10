//! # englobe-bench
//!
//! englobe measured side by side with Intel Embree (behind the `embree` feature), obvhs and bvh,
//! all on the same rays: the three ray sets of [`rays`] are generated once per scene from a fixed
//! seed, every library in [`adapters`] traces them on 1 and 2 threads (or any counts), the
//! answers of the timed runs are checked against englobe's brute force ([`agreement`]), and
//! [`run`](fn@run) prints a table per scene and thread count and writes one CSV row per
//! measurement ([`results`]). `docs/performance.md` describes the method and the figures.

pub mod adapters;
pub mod agreement;
pub mod cli;
pub mod library;
pub mod measure;
pub mod rays;
pub mod registry;
pub mod report;
pub mod results;
pub mod rng;
pub mod run;
pub mod scene;

pub use cli::BenchArgs;
pub use library::{BenchRay, Library, RayResult};
pub use rays::{RaySetKind, RaySets};
pub use registry::{BuildSettings, LibraryKind, build_library};
pub use run::run;
pub use scene::BenchScene;
