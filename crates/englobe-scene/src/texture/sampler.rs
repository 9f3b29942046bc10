//! How a texture is read between and beyond its texels: the glTF 2.0 sampler (section 3.8.4,
//! "Samplers"). Wrap modes per axis (repeat, mirrored repeat, clamp to edge, with the meanings
//! OpenGL gives them), and bilinear or nearest filtering with texel centres at
//! `((i + 0.5) / width, (j + 0.5) / height)`. The same bilinear filter reads the levels of a mip
//! pyramid (see [`super::filtered`]), through [`Grid`]; without a footprint (the scene's
//! `texture_filter = "none"`), minification filters of the file are read as bilinear.

use glam::{Vec2, Vec4};

use super::image::{ColorSpace, TexelImage};

/// What happens to coordinates outside `0..1` along one axis.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum Wrap {
    /// The image tiles the plane (glTF's default, `REPEAT` 10497).
    #[default]
    Repeat,
    /// Every other tile is mirrored (`MIRRORED_REPEAT` 33648).
    MirroredRepeat,
    /// The edge texels extend forever (`CLAMP_TO_EDGE` 33071).
    ClampToEdge,
}

/// How texels are combined.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum Filter {
    /// The four nearest texels weighted by distance.
    #[default]
    Bilinear,
    /// The texel the point falls in.
    Nearest,
}

/// A sampler: a wrap mode per axis and a filter.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub struct Sampler {
    /// Along `u` (across the image).
    pub wrap_u: Wrap,
    /// Along `v` (down the image).
    pub wrap_v: Wrap,
    /// Filter.
    pub filter: Filter,
}

impl Wrap {
    /// Texel index `i` (any integer) folded into `0..n`.
    #[inline]
    pub fn index(self, i: i64, n: u32) -> u32 {
        let n = n as i64;
        (match self {
            Wrap::Repeat => i.rem_euclid(n),
            Wrap::ClampToEdge => i.clamp(0, n - 1),
            Wrap::MirroredRepeat => {
                let m = i.rem_euclid(2 * n);
                if m < n { m } else { 2 * n - 1 - m }
            }
        }) as u32
    }
}

/// A grid of texels that a sampler reads: an image in one colour space, or a mip level.
pub(crate) trait Grid {
    /// Width and height in texels.
    fn size(&self) -> (u32, u32);
    /// Texel `(x, y)` as linear RGBA; `x` and `y` inside the grid.
    fn texel(&self, x: u32, y: u32) -> Vec4;
}

impl Grid for (&TexelImage, ColorSpace) {
    #[inline]
    fn size(&self) -> (u32, u32) {
        (self.0.width(), self.0.height())
    }
    #[inline]
    fn texel(&self, x: u32, y: u32) -> Vec4 {
        self.0.fetch(x, y, self.1)
    }
}

impl Sampler {
    /// A sampler with one wrap mode on both axes and bilinear filtering.
    pub fn wrapping(wrap: Wrap) -> Self {
        Sampler { wrap_u: wrap, wrap_v: wrap, filter: Filter::Bilinear }
    }

    /// The filtered value of `image` at `uv` (see the module's conventions), linear RGBA.
    /// Coordinates that are not finite read texel `(0, 0)`.
    pub fn sample(&self, image: &TexelImage, uv: Vec2, space: ColorSpace) -> Vec4 {
        self.sample_grid(&(image, space), uv, self.filter)
    }

    /// The value of `grid` at `uv` through `filter`, with this sampler's wrap modes.
    #[inline]
    pub(crate) fn sample_grid<G: Grid>(&self, grid: &G, uv: Vec2, filter: Filter) -> Vec4 {
        let (w, h) = grid.size();
        let uv = if uv.is_finite() { uv } else { Vec2::ZERO };
        // Far outside the image, f32 loses the fraction; keep the coordinates where i64 and f32
        // agree (the wrap is periodic, so this changes nothing for repeating modes within the
        // precision left, and clamping is unaffected).
        let x = (uv.x as f64 * w as f64).clamp(-1e15, 1e15);
        let y = (uv.y as f64 * h as f64).clamp(-1e15, 1e15);
        match filter {
            Filter::Nearest => {
                let i = self.wrap_u.index(x.floor() as i64, w);
                let j = self.wrap_v.index(y.floor() as i64, h);
                grid.texel(i, j)
            }
            Filter::Bilinear => {
                let (x, y) = (x - 0.5, y - 0.5);
                let (x0, y0) = (x.floor(), y.floor());
                let (fx, fy) = ((x - x0) as f32, (y - y0) as f32);
                let (x0, y0) = (x0 as i64, y0 as i64);
                let (i0, i1) = (self.wrap_u.index(x0, w), self.wrap_u.index(x0 + 1, w));
                let (j0, j1) = (self.wrap_v.index(y0, h), self.wrap_v.index(y0 + 1, h));
                let top = grid.texel(i0, j0).lerp(grid.texel(i1, j0), fx);
                let bottom = grid.texel(i0, j1).lerp(grid.texel(i1, j1), fx);
                top.lerp(bottom, fy)
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A 4 x 2 grey ramp: texel (i, j) holds 10 * i + 100 * j in red, in 8 bits.
    fn ramp() -> TexelImage {
        let texels = (0..2).flat_map(|j| (0..4).map(move |i| [10 * i + 100 * j, 0, 0, 255])).collect();
        TexelImage::from_rgba8(4, 2, texels).unwrap()
    }

    fn red(s: Sampler, u: f32, v: f32) -> f32 {
        s.sample(&ramp(), Vec2::new(u, v), ColorSpace::Linear).x * 255.0
    }

    #[test]
    fn wrap_indices_by_hand() {
        let got = |w: Wrap| (-5..9).map(|i| w.index(i, 4)).collect::<Vec<_>>();
        assert_eq!(got(Wrap::Repeat), [3, 0, 1, 2, 3, 0, 1, 2, 3, 0, 1, 2, 3, 0]);
        assert_eq!(got(Wrap::ClampToEdge), [0, 0, 0, 0, 0, 0, 1, 2, 3, 3, 3, 3, 3, 3]);
        assert_eq!(got(Wrap::MirroredRepeat), [3, 3, 2, 1, 0, 0, 1, 2, 3, 3, 2, 1, 0, 0]);
    }

    #[test]
    fn texel_centres_return_the_texel() {
        let s = Sampler::default();
        for j in 0..2 {
            for i in 0..4 {
                let (u, v) = ((i as f32 + 0.5) / 4.0, (j as f32 + 0.5) / 2.0);
                assert!((red(s, u, v) - (10 * i + 100 * j) as f32).abs() < 1e-3, "{i} {j}");
            }
        }
    }

    #[test]
    fn bilinear_midpoints() {
        let s = Sampler::default();
        // Halfway between the centres of texels 1 and 2 of the top row: (10 + 20) / 2.
        assert!((red(s, 0.5, 0.25) - 15.0).abs() < 1e-3);
        // The middle of the image: the mean of texels (1,0), (2,0), (1,1), (2,1).
        assert!((red(s, 0.5, 0.5) - (10.0 + 20.0 + 110.0 + 120.0) / 4.0).abs() < 1e-3);
        // A quarter of the way from the centre of texel 0 to texel 1.
        assert!((red(s, (0.5 + 0.25) / 4.0, 0.25) - 2.5).abs() < 1e-3);
    }

    #[test]
    fn the_left_edge_by_wrap_mode() {
        // u = 0 is halfway between texel 0 and the texel "before" it, which each mode names.
        let at_edge = |w: Wrap| red(Sampler::wrapping(w), 0.0, 0.25);
        assert!((at_edge(Wrap::Repeat) - 15.0).abs() < 1e-3, "texels 3 and 0: (30 + 0) / 2");
        assert!(at_edge(Wrap::ClampToEdge).abs() < 1e-3, "texel 0 twice");
        assert!(at_edge(Wrap::MirroredRepeat).abs() < 1e-3, "texel 0 and its mirror, texel 0");
        // One and a quarter: repeat reads u = 0.25; mirrored repeat reads 0.75; clamp the last texel.
        let far = |w: Wrap| red(Sampler::wrapping(w), 1.0 + 0.375, 0.25);
        assert!((far(Wrap::Repeat) - 10.0).abs() < 1e-3);
        assert!((far(Wrap::MirroredRepeat) - 20.0).abs() < 1e-3);
        assert!((far(Wrap::ClampToEdge) - 30.0).abs() < 1e-3);
        // Per axis: clamp down the image, repeat across it.
        let mixed = Sampler { wrap_u: Wrap::Repeat, wrap_v: Wrap::ClampToEdge, filter: Filter::Bilinear };
        assert!((red(mixed, 0.125 - 1.0, 7.0) - 100.0).abs() < 1e-3);
        assert!((red(mixed, 0.125, -3.0) - 0.0).abs() < 1e-3);
    }

    #[test]
    fn nearest_and_non_finite() {
        let s = Sampler { filter: Filter::Nearest, ..Sampler::default() };
        assert_eq!(red(s, 0.49, 0.6), 110.0);
        assert_eq!(red(s, -0.01, 0.0), 30.0);
        assert_eq!(red(Sampler::default(), f32::NAN, 0.0), red(Sampler::default(), 0.0, 0.0));
    }
}
