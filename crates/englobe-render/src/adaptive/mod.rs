//! Adaptive sampling to a noise threshold (the scene's `[image] noise_threshold`, as Cycles' and
//! RenderMan's): every pixel takes a first pass of samples, then only the blocks of pixels whose
//! estimated relative error is still above the threshold take more, pass after pass, up to the
//! scene's `samples`. The estimate and the schedule are in [`estimator`], the passes in
//! [`render`]; [`crate::Renderer::render`] and [`crate::Renderer::render_passes`] use them
//! whenever the scene sets a threshold.

pub mod estimator;
pub mod render;

pub use estimator::{AdaptiveSampling, BLOCK_SIZE, HalfSums, block_error, default_min_samples};
pub use render::covering_blocks;
