//! Reading a texture over a footprint: the area of the texture that one ray's cone covers (see
//! englobe-render's `ray_cone`), an ellipse given by two half-axes in texture coordinates.
//!
//! The ellipse is read the way hardware anisotropic filtering reads it, by footprint assembly
//! (Schilling, Knittel and Strasser 1996, "Texram: A Smart Memory for Texturing"): up to
//! [`MAX_ANISOTROPY`] trilinear probes spaced along the major axis, each at the level of detail
//! of the minor axis (or of the spacing, when the ratio of the axes is over the cap), averaged.
//! A trilinear probe (Williams 1983, "Pyramidal Parametrics") reads the two mip levels around
//! its level of detail bilinearly and blends them. The level of detail is `log2` of the
//! footprint's diameter in texels of the image: level 0 (the image) for a footprint of one
//! texel, level `k` for `2^k` texels. A footprint within one texel reads the image as an
//! unfiltered lookup does (the sampler's own filter, bilinear or nearest), so magnified textures
//! look the same with and without footprints.

use glam::{Vec2, Vec4};

use super::image::{ColorSpace, TexelImage};
use super::mip::{MipLevel, MipPyramid};
use super::sampler::{Filter, Grid, Sampler};

/// Most probes along the major axis of a footprint (hardware's usual 8:1 or 16:1 cap): a
/// narrower ellipse is read at a coarser level instead, blurring it along its minor axis.
pub const MAX_ANISOTROPY: u32 = 8;

/// The footprint of a lookup: an ellipse centred on the lookup point, given by two half-axes in
/// texture coordinates (glTF convention, one unit across the image).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct UvFootprint {
    /// The two half-axes (not necessarily perpendicular once mapped by a skewed parametrisation;
    /// the longer is taken as the major axis).
    pub axes: [Vec2; 2],
}

impl UvFootprint {
    /// The footprint after a linear map of texture coordinates (the linear part of a texture
    /// transform).
    pub fn mapped(self, linear: impl Fn(Vec2) -> Vec2) -> Self {
        UvFootprint { axes: self.axes.map(linear) }
    }
}

/// How a footprint is read from an image of a given size.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FilterPlan {
    /// Probes along the major axis, `1..=MAX_ANISOTROPY`.
    pub probes: u32,
    /// Level of detail of each probe: `log2` of its diameter in texels of the image (at most 0
    /// reads the image itself).
    pub lod: f32,
    /// Texture-coordinate step between neighbouring probes.
    pub step: Vec2,
}

impl FilterPlan {
    /// The plan for `footprint` on a `width` x `height` image; `None` when the footprint is not
    /// finite (a degenerate parametrisation), which the caller reads as no footprint.
    pub fn new(footprint: UvFootprint, width: u32, height: u32) -> Option<Self> {
        let size = Vec2::new(width as f32, height as f32);
        let [a, b] = footprint.axes;
        let (ta, tb) = ((a * size).length(), (b * size).length());
        if !(ta.is_finite() && tb.is_finite()) {
            return None;
        }
        let (major, long, short) = if ta >= tb { (a, ta, tb) } else { (b, tb, ta) };
        // A footprint within one texel is one probe: spreading probes inside a texel would only
        // blur what the bilinear filter already shows.
        let probes = if long <= short || 2.0 * long <= 1.0 {
            1
        } else if short > 0.0 {
            (long / short).ceil().min(MAX_ANISOTROPY as f32) as u32
        } else {
            MAX_ANISOTROPY
        };
        let diameter = if probes == 1 { 2.0 * long } else { (2.0 * long / probes as f32).max(2.0 * short) };
        Some(FilterPlan { probes, lod: diameter.log2(), step: major * (2.0 / probes as f32) })
    }
}

impl Grid for MipLevel {
    #[inline]
    fn size(&self) -> (u32, u32) {
        (self.width(), self.height())
    }
    #[inline]
    fn texel(&self, x: u32, y: u32) -> Vec4 {
        self.fetch(x, y)
    }
}

/// The value of `image` (read through `sampler`, in `space`, its levels in `pyramid`) over
/// `footprint` centred at `uv`. `pyramid` is called only when a level below the image is read.
pub fn sample_footprint<'p>(
    sampler: &Sampler,
    image: &TexelImage,
    pyramid: impl FnOnce() -> &'p MipPyramid,
    uv: Vec2,
    footprint: UvFootprint,
    space: ColorSpace,
) -> Vec4 {
    let Some(plan) = FilterPlan::new(footprint, image.width(), image.height()) else {
        return sampler.sample(image, uv, space);
    };
    let magnified = !(plan.lod > 0.0);
    if magnified && plan.probes == 1 {
        return sampler.sample(image, uv, space);
    }
    let levels = if magnified { &[][..] } else { pyramid().levels() };
    let lod = if magnified { 0.0 } else { plan.lod.min(levels.len() as f32) };
    let probe = |uv: Vec2| -> Vec4 {
        if lod <= 0.0 {
            return sampler.sample(image, uv, space);
        }
        let k = lod.floor() as usize;
        let read = |k: usize| match k {
            0 => sampler.sample_grid(&(image, space), uv, Filter::Bilinear),
            _ => sampler.sample_grid(&levels[k - 1], uv, Filter::Bilinear),
        };
        let f = lod - k as f32;
        if f > 0.0 && k < levels.len() { read(k).lerp(read(k + 1), f) } else { read(k) }
    };
    let first = -(plan.probes as f32 - 1.0) * 0.5;
    let mut sum = Vec4::ZERO;
    for i in 0..plan.probes {
        sum += probe(uv + plan.step * (first + i as f32));
    }
    sum / plan.probes as f32
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::texture::Wrap;

    fn footprint(a: [f32; 2], b: [f32; 2]) -> UvFootprint {
        UvFootprint { axes: [Vec2::from(a), Vec2::from(b)] }
    }

    #[test]
    fn plans_by_hand() {
        // A circle 8 texels across on a 64 x 64 image: one probe at level 3.
        let p = FilterPlan::new(footprint([4.0 / 64.0, 0.0], [0.0, 4.0 / 64.0]), 64, 64).unwrap();
        assert_eq!((p.probes, p.lod), (1, 3.0));
        // An ellipse 32 by 8 texels on a 64 x 32 image: four probes 8 texels apart, at level 3.
        let p = FilterPlan::new(footprint([0.0, 4.0 / 32.0], [16.0 / 64.0, 0.0]), 64, 32).unwrap();
        assert_eq!((p.probes, p.lod), (4, 3.0));
        assert!((p.step - Vec2::new(8.0 / 64.0, 0.0)).length() < 1e-7);
        // 64 by 2 texels: over the cap, so 8 probes of 8 texels (level 3), not 32 of 2.
        let p = FilterPlan::new(footprint([32.0 / 64.0, 0.0], [0.0, 1.0 / 64.0]), 64, 64).unwrap();
        assert_eq!((p.probes, p.lod), (MAX_ANISOTROPY, 3.0));
        assert!(FilterPlan::new(footprint([f32::INFINITY, 0.0], [0.0, 1.0]), 4, 4).is_none());
    }

    /// A `n` x `n` checkerboard of black and white 8-bit texels.
    fn checker(n: u32) -> TexelImage {
        let t = (0..n * n).map(|i| if (i % n + i / n) % 2 == 0 { [255; 4] } else { [0, 0, 0, 255] }).collect();
        TexelImage::from_rgba8(n, n, t).unwrap()
    }

    #[test]
    fn wide_footprints_read_the_mean_and_small_ones_the_texel() {
        let img = checker(16);
        let pyramid = MipPyramid::build(&img, ColorSpace::Linear);
        let s = Sampler::default();
        let at = |uv: Vec2, r: f32| {
            sample_footprint(&s, &img, || &pyramid, uv, footprint([r, 0.0], [0.0, r]), ColorSpace::Linear).x
        };
        // The whole image or more: the last level, the checkerboard's mean.
        assert!((at(Vec2::new(0.3, 0.7), 0.5) - 0.5).abs() < 1e-6);
        assert!((at(Vec2::new(0.3, 0.7), 40.0) - 0.5).abs() < 1e-6);
        // Under a texel: the texel itself, as without a footprint.
        let centre = Vec2::new(2.5 / 16.0, 4.5 / 16.0);
        assert_eq!(at(centre, 0.2 / 16.0), s.sample(&img, centre, ColorSpace::Linear).x);
        assert_eq!(at(centre, 0.2 / 16.0), 1.0);
        // Two texels across (level 1, every texel of which is grey): the mean at any point.
        assert!((at(Vec2::new(0.37, 0.61), 1.0 / 16.0) - 0.5).abs() < 1e-6);
    }

    #[test]
    fn levels_wrap_as_the_sampler_says_at_odd_sizes() {
        // A 6 x 1 strip of red 0, 0, 0, 90, 90, 90: level 1 is the odd-sized 0, 45, 90.
        let t = [0u8, 0, 0, 90, 90, 90].map(|r| [r, 0, 0, 255]).to_vec();
        let img = TexelImage::from_rgba8(6, 1, t).unwrap();
        let pyramid = MipPyramid::build(&img, ColorSpace::Linear);
        let l1: Vec<f32> = (0..3).map(|x| pyramid.levels()[0].fetch(x, 0).x * 255.0).collect();
        assert!((l1[0] - 0.0).abs() < 1e-4 && (l1[1] - 45.0).abs() < 1e-4 && (l1[2] - 90.0).abs() < 1e-4);
        // At u = 0, exactly level 1 (a footprint 2 texels across): halfway between level 1's
        // first texel and the one before it, which repeat takes from the far end and clamp from
        // the edge. The odd-sized level wraps with its own width.
        let read = |wrap: Wrap| {
            let s = Sampler::wrapping(wrap);
            let fp = footprint([1.0 / 6.0, 0.0], [0.0, 1.0 / 6.0]);
            sample_footprint(&s, &img, || &pyramid, Vec2::new(0.0, 0.5), fp, ColorSpace::Linear).x * 255.0
        };
        assert!((read(Wrap::Repeat) - 45.0).abs() < 1e-3, "(90 + 0) / 2");
        assert!(read(Wrap::ClampToEdge).abs() < 1e-3, "texel 0 twice");
        assert!(read(Wrap::MirroredRepeat).abs() < 1e-3, "texel 0 and its mirror");
    }

    #[test]
    fn an_anisotropic_footprint_keeps_detail_across_its_minor_axis() {
        // Vertical stripes one texel wide (columns alternate), read with an ellipse 8 texels long
        // along v (across no stripe) and one texel wide along u: eight probes down the stripe
        // at level 0 read it white, where a round footprint of the long axis reads grey.
        let n = 32;
        let t = (0..n * n).map(|i| if (i % n) % 2 == 0 { [255; 4] } else { [0, 0, 0, 255] }).collect();
        let img = TexelImage::from_rgba8(n, n, t).unwrap();
        let pyramid = MipPyramid::build(&img, ColorSpace::Linear);
        let s = Sampler::default();
        let uv = Vec2::new(4.5 / 32.0, 0.5);
        let thin = footprint([0.0, 4.0 / 32.0], [0.5 / 32.0, 0.0]);
        let round = footprint([0.0, 4.0 / 32.0], [4.0 / 32.0, 0.0]);
        let v = |fp| sample_footprint(&s, &img, || &pyramid, uv, fp, ColorSpace::Linear).x;
        assert!(v(thin) > 0.95, "{}", v(thin));
        assert!((v(round) - 0.5).abs() < 1e-3, "{}", v(round));
    }
}
