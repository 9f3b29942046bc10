//! The mip pyramid of an image (Williams 1983, "Pyramidal Parametrics"): the image at half, a
//! quarter, ... of its size, down to one texel, so that a lookup whose footprint covers many
//! texels reads a few texels of a smaller level instead of aliasing between them.
//!
//! Each level is a box filter of the one above, in linear values: an sRGB texture is decoded
//! before it is averaged (averaging the encoded codes would darken every edge). A level of
//! `m = max(1, n / 2)` texels along an axis of `n` covers the same span as its parent, so texel
//! `i` averages the parent's interval `[i n / m, (i + 1) n / m)`, the texels it overlaps weighted
//! by their overlap: two halves for even sizes (the classic 2 x 2 average), a texel shared by
//! two children for odd ones. The box never reaches past an edge, which is why one pyramid
//! serves every sampler that reads the image, whatever its wrap modes (textures of one decoded
//! image may wrap differently): the wrap modes act when a level is read, as they do on the image
//! itself (see [`super::sampler`]).

use std::sync::{Arc, OnceLock};

use glam::Vec4;

use super::image::{ColorSpace, TexelImage};

/// One level below the image: linear RGBA texels, rows from the top.
#[derive(Clone, Debug, PartialEq)]
pub struct MipLevel {
    width: u32,
    height: u32,
    texels: Vec<Vec4>,
}

impl MipLevel {
    /// Width in texels.
    pub fn width(&self) -> u32 {
        self.width
    }

    /// Height in texels.
    pub fn height(&self) -> u32 {
        self.height
    }

    /// Texel `(x, y)`, linear; the caller keeps it inside the level.
    #[inline]
    pub fn fetch(&self, x: u32, y: u32) -> Vec4 {
        self.texels[y as usize * self.width as usize + x as usize]
    }
}

/// The levels below an image, for one colour space: `levels()[0]` is level 1 (half the size),
/// the last is one texel wide and high. An image of one texel has none.
#[derive(Clone, Debug, PartialEq)]
pub struct MipPyramid {
    levels: Vec<MipLevel>,
}

impl MipPyramid {
    /// The pyramid of `image` read in `space`.
    pub fn build(image: &TexelImage, space: ColorSpace) -> Self {
        let mut levels: Vec<MipLevel> = Vec::new();
        let (mut w, mut h) = (image.width(), image.height());
        while w > 1 || h > 1 {
            let next = match levels.last() {
                None => downsample(w, h, |x, y| image.fetch(x, y, space)),
                Some(l) => downsample(w, h, |x, y| l.fetch(x, y)),
            };
            (w, h) = (next.width, next.height);
            levels.push(next);
        }
        MipPyramid { levels }
    }

    /// The levels below the image.
    pub fn levels(&self) -> &[MipLevel] {
        &self.levels
    }
}

/// A texture's pyramids, one per colour space it is read in, each built the first time a
/// filtered lookup needs it and kept for the rest of the scene's life. Built on demand rather
/// than when the image is decoded because the colour space belongs to the material slot that
/// reads the texture, not to the image, and because renders without footprints (the scene's
/// `texture_filter = "none"`) never read a level. Clones share the pyramids. It compares equal
/// and prints the same whether built or not: it is a cache of the image, not part of the scene.
#[derive(Clone, Default)]
pub struct MipCache(Arc<[OnceLock<MipPyramid>; 2]>);

impl MipCache {
    /// The pyramid of `image` in `space`, built on first use.
    pub fn get(&self, image: &TexelImage, space: ColorSpace) -> &MipPyramid {
        let slot = match space {
            ColorSpace::Srgb => &self.0[0],
            ColorSpace::Linear => &self.0[1],
        };
        slot.get_or_init(|| MipPyramid::build(image, space))
    }
}

impl PartialEq for MipCache {
    fn eq(&self, _: &Self) -> bool {
        true
    }
}

impl std::fmt::Debug for MipCache {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str("MipCache")
    }
}

/// For each texel of a level of `m` texels along an axis of `n`, the parent texels it covers and
/// their weights (summing to 1).
fn box_weights(n: u32) -> (u32, Vec<Vec<(u32, f32)>>) {
    let m = (n / 2).max(1);
    let scale = n as f64 / m as f64;
    let weights = (0..m)
        .map(|i| {
            let (lo, hi) = (i as f64 * scale, (i + 1) as f64 * scale);
            (lo.floor() as u32..(hi.ceil() as u32).min(n))
                .filter_map(|k| {
                    let overlap = (hi.min(k as f64 + 1.0) - lo.max(k as f64)).max(0.0);
                    (overlap > 0.0).then_some((k, (overlap / scale) as f32))
                })
                .collect()
        })
        .collect();
    (m, weights)
}

/// The level below a `w` x `h` level whose texels `fetch` reads.
fn downsample(w: u32, h: u32, fetch: impl Fn(u32, u32) -> Vec4) -> MipLevel {
    let (mw, wx) = box_weights(w);
    let (mh, wy) = box_weights(h);
    let mut texels = Vec::with_capacity(mw as usize * mh as usize);
    for row in &wy {
        for col in &wx {
            let mut sum = Vec4::ZERO;
            for &(y, fy) in row {
                for &(x, fx) in col {
                    sum += fetch(x, y) * (fx * fy);
                }
            }
            texels.push(sum);
        }
    }
    MipLevel { width: mw, height: mh, texels }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn red_ramp(w: u32, h: u32, value: impl Fn(u32, u32) -> u8) -> TexelImage {
        let texels = (0..h).flat_map(|y| (0..w).map(|x| [value(x, y), 0, 0, 255]).collect::<Vec<_>>()).collect();
        TexelImage::from_rgba8(w, h, texels).unwrap()
    }

    fn reds(l: &MipLevel) -> Vec<f32> {
        (0..l.height())
            .flat_map(|y| (0..l.width()).map(move |x| (l.fetch(x, y).x * 255.0 * 1000.0).round() / 1000.0))
            .collect()
    }

    #[test]
    fn even_sizes_average_two_by_two() {
        // A 4 x 2 image: texel (x, y) = 10 x + 100 y.
        let p = MipPyramid::build(&red_ramp(4, 2, |x, y| (10 * x + 100 * y) as u8), ColorSpace::Linear);
        let sizes: Vec<_> = p.levels().iter().map(|l| (l.width(), l.height())).collect();
        assert_eq!(sizes, [(2, 1), (1, 1)]);
        // (0 + 10 + 100 + 110) / 4 and (20 + 30 + 120 + 130) / 4; then their mean.
        assert_eq!(reds(&p.levels()[0]), [55.0, 75.0]);
        assert_eq!(reds(&p.levels()[1]), [65.0]);
    }

    #[test]
    fn odd_sizes_share_the_middle_texel() {
        // A 5 x 3 image of red = 10 x + 50 y. Level 1 is 2 x 1: texel 0 covers columns 0, 1 and
        // half of 2 (weights 1, 1, 0.5 out of 2.5), rows 0..3 equally.
        let p = MipPyramid::build(&red_ramp(5, 3, |x, y| (10 * x + 50 * y) as u8), ColorSpace::Linear);
        let l1 = &p.levels()[0];
        assert_eq!((l1.width(), l1.height()), (2, 1));
        let row_mean = 50.0; // (0 + 50 + 100) / 3
        let left = (0.0 + 10.0 + 0.5 * 20.0) / 2.5 + row_mean;
        let right = (0.5 * 20.0 + 30.0 + 40.0) / 2.5 + row_mean;
        let got = reds(l1);
        assert!((got[0] - left).abs() < 1e-3 && (got[1] - right).abs() < 1e-3, "{got:?}");
        // The last level is the mean of the whole image.
        let last = p.levels().last().unwrap();
        assert_eq!((last.width(), last.height()), (1, 1));
        assert!((reds(last)[0] - (20.0 + row_mean)).abs() < 1e-3);
        // A 3 x 1 strip: one texel, the mean of three; a 1 x 1 image has no level below it.
        let strip = MipPyramid::build(&red_ramp(3, 1, |x, _| (30 * x) as u8), ColorSpace::Linear);
        assert_eq!(reds(&strip.levels()[0]), [30.0]);
        assert!(MipPyramid::build(&red_ramp(1, 1, |_, _| 7), ColorSpace::Linear).levels().is_empty());
    }

    #[test]
    fn srgb_levels_average_light_not_codes() {
        // Black and white sRGB texels average to linear one half (code 188), not to code 128.
        let img = TexelImage::from_rgba8(2, 1, vec![[0, 0, 0, 255], [255, 255, 255, 0]]).unwrap();
        let l = MipPyramid::build(&img, ColorSpace::Srgb).levels()[0].fetch(0, 0);
        assert!((l.x - 0.5).abs() < 1e-6 && (l.w - 0.5).abs() < 1e-6, "{l}");
        let l = MipPyramid::build(&img, ColorSpace::Linear).levels()[0].fetch(0, 0);
        assert!((l.x - 0.5).abs() < 1e-6);
    }
}
