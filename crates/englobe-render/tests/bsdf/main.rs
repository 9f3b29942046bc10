//! The BSDFs checked as pbrt-v4 (`src/pbrt/bsdfs_test.cpp`) and Mitsuba 3 (`chi2.py`) check
//! theirs: chi-square goodness of fit of every sampler against its density, the sampling weights
//! against `eval`, the densities' integrals, energy conservation, reciprocity, and closed forms.
//!
//! `cargo test -p englobe-render bsdf` runs these and the unit tests of `englobe_render::bsdf`.

mod bsdf_cases;
mod bsdf_chi2;
mod bsdf_closed_forms;
mod bsdf_energy;
mod bsdf_reciprocity;
mod bsdf_stats;
mod bsdf_weights;
