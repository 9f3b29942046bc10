//! # englobe-lab
//!
//! englobe's research, as a library: the seed report's experiment ([`seed_experiment`], on the
//! scenes and figures of [`seed_report`]), its other family of speed-ups, fewer rays
//! ([`fewer_rays`], [`fewer_samples`] for the path tracer's adaptive sampling and [`ray_cones`]
//! for texture filtering by ray cones, with
//! [`image_error`] saying what an image loses), the pixel samplers' errors ([`samplers`]) and the comparison of every acceleration structure on one
//! scene ([`compare`]), both built on [`measure`] (build, render, time, compare images); their
//! reports ([`report`]: tables and JSON; [`html_report`]: the comparison and the seed experiment, each
//! as one self-contained page) and plot ([`plot`]: SVG). The `englobe` command parses its
//! arguments and calls these; a program can call them as well:
//!
//! ```no_run
//! use englobe_lab::{SeedOptions, run_seed};
//!
//! let options = SeedOptions { size: Some(64), tests: vec![1], ..SeedOptions::default() };
//! let experiment = run_seed(&options, &mut |line| eprintln!("{line}"))?;
//! print!("{}{}", experiment.table(), experiment.claims());
//! assert!(experiment.images_identical());
//! # Ok::<(), englobe_lab::LabError>(())
//! ```
//!
//! [`error`] is the bottom module and [`seed_experiment`] and [`html_report`] the top ones; no module
//! imports one above it.

pub mod compare;
pub mod error;
pub mod fewer_rays;
pub mod fewer_samples;
pub mod html_report;
pub mod image_error;
pub mod measure;
pub mod memory;
pub mod plot;
pub mod ray_cones;
pub mod report;
pub mod samplers;
pub mod seed_experiment;
pub mod seed_report;

pub use compare::{CompareOptions, CompareRow, Comparison, run_compare};
pub use error::LabError;
pub use fewer_rays::{FewerRays, FewerRaysOptions, run_fewer_rays};
pub use samplers::{SamplerExperiment, SamplerOptions, run_samplers};
pub use seed_experiment::{SeedExperiment, SeedOptions, SeedRow, run_seed};
