//! The pixel reconstruction filter a scene asks for (`[image] filter`): which samples a pixel
//! averages, as an offset from its centre drawn from the filter's shape (filter importance
//! sampling, as pbrt-v4 does; see englobe-render's `filter.rs`). The box of radius 0.5, samples
//! uniform over the pixel, is the default.

use englobe::Vec2;

/// Largest filter radius accepted, in pixels.
pub const MAX_FILTER_RADIUS: f32 = 16.0;

/// A pixel filter, separable in x and y, with its radius (half-width) in pixels on each axis.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum PixelFilter {
    /// Constant over `[-r, r]`.
    Box {
        /// Radius on each axis.
        radius: Vec2,
    },
    /// The tent `max(0, r - |x|)` on each axis.
    Triangle {
        /// Radius on each axis.
        radius: Vec2,
    },
    /// `max(0, g(x) - g(r))` on each axis, with `g` the Gaussian of standard deviation `sigma`
    /// (pbrt-v4's `GaussianFilter`: the Gaussian lowered to reach zero at the radius).
    Gaussian {
        /// Radius on each axis.
        radius: Vec2,
        /// Standard deviation, in pixels.
        sigma: f32,
    },
}

impl Default for PixelFilter {
    /// The box of radius 0.5: samples uniform over the pixel.
    fn default() -> Self {
        PixelFilter::Box { radius: Vec2::splat(0.5) }
    }
}

impl PixelFilter {
    /// The name used in scene files.
    pub fn name(&self) -> &'static str {
        match self {
            PixelFilter::Box { .. } => "box",
            PixelFilter::Triangle { .. } => "triangle",
            PixelFilter::Gaussian { .. } => "gaussian",
        }
    }

    /// The radius on each axis.
    pub fn radius(&self) -> Vec2 {
        match *self {
            PixelFilter::Box { radius } | PixelFilter::Triangle { radius } | PixelFilter::Gaussian { radius, .. } => {
                radius
            }
        }
    }

    /// The filter named `name` with `radius` (or the kind's default: 0.5 for the box, 2 for the
    /// triangle, 1.5 for the Gaussian, pbrt's) and, for the Gaussian, `sigma` (default 0.5).
    pub fn named(name: &str, radius: Option<Vec2>, sigma: Option<f32>) -> Option<Self> {
        Some(match name {
            "box" => PixelFilter::Box { radius: radius.unwrap_or(Vec2::splat(0.5)) },
            "triangle" => PixelFilter::Triangle { radius: radius.unwrap_or(Vec2::splat(2.0)) },
            "gaussian" => {
                PixelFilter::Gaussian { radius: radius.unwrap_or(Vec2::splat(1.5)), sigma: sigma.unwrap_or(0.5) }
            }
            _ => return None,
        })
    }

    /// Checks the radius (more than 0, at most [`MAX_FILTER_RADIUS`]) and sigma (more than 0).
    pub fn check(&self) -> Result<(), String> {
        let r = self.radius();
        if !(r.min_element() > 0.0 && r.max_element() <= MAX_FILTER_RADIUS) {
            return Err(format!("filter radius {r}: expected more than 0 and at most {MAX_FILTER_RADIUS} pixels"));
        }
        if let PixelFilter::Gaussian { sigma, .. } = *self
            && !(sigma > 0.0 && sigma.is_finite())
        {
            return Err(format!("Gaussian sigma {sigma}: expected more than 0"));
        }
        Ok(())
    }
}
