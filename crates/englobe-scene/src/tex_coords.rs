//! Texture coordinate sets at one point of a surface. A mesh keeps up to two sets (glTF's
//! `TEXCOORD_0` and `TEXCOORD_1`; OBJ and PLY files have one), and each texture of a material
//! reads the set its [`TextureRef::uv_set`] names: a glTF file may map its base colour with one
//! set and its occlusion or a decal with another. [`TexCoords`] carries both sets' coordinates
//! at a hit, each with its own ray-cone footprint (the two sets stretch differently over the same
//! triangle), and answers every reference with the set it asks for.
//!
//! Set 1 falls back to set 0 where the point has no set 1: a mesh without a second set is read
//! as glTF readers that keep one set read it, and the loader says so in a warning.

use glam::Vec2;

use crate::material::{MaterialTextures, TextureRef};
use crate::texture::UvFootprint;

/// The texture coordinates of one point in sets 0 and 1, with their footprints.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct TexCoords {
    /// Sets 0 and 1 (glTF convention: `(0, 0)` the image's top-left corner, `v` down); `None`
    /// where the mesh has no such set.
    pub uv: [Option<Vec2>; 2],
    /// The footprint of a ray's cone in each set (see [`crate::texture::sample_footprint`]);
    /// `None` reads the texture at the point.
    pub footprint: [Option<UvFootprint>; 2],
}

impl TexCoords {
    /// One coordinate and footprint that every texture reads, whatever its set: a mesh with one
    /// set (set 1 falls back to it).
    pub fn one(uv: Option<Vec2>, footprint: Option<UvFootprint>) -> Self {
        TexCoords { uv: [uv, None], footprint: [footprint, None] }
    }

    /// The coordinate and footprint that `r` reads: set 1 if it asks for it and the point has
    /// it, set 0 otherwise.
    #[inline]
    pub fn of(&self, r: &TextureRef) -> (Option<Vec2>, Option<UvFootprint>) {
        let set = usize::from(r.uv_set == 1 && self.uv[1].is_some());
        (self.uv[set], self.footprint[set])
    }
}

impl From<Option<Vec2>> for TexCoords {
    /// [`TexCoords::one`] without a footprint.
    fn from(uv: Option<Vec2>) -> Self {
        TexCoords::one(uv, None)
    }
}

impl MaterialTextures {
    /// Whether some slot reads texture coordinate set 1 (so that a hit needs it).
    pub fn reads_set1(&self) -> bool {
        self.refs().into_iter().flatten().any(|r| r.uv_set == 1)
    }

    /// The set the coverage is read with: the alpha texture's (MTL `map_d`) when there is one,
    /// else the base colour texture's, whose alpha is glTF's coverage.
    pub fn coverage_set(&self) -> u32 {
        match (&self.alpha, &self.base_color) {
            (Some(a), _) => a.texture.uv_set,
            (None, Some(b)) => b.uv_set,
            (None, None) => 0,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::material::{Channel, ScalarTexture};

    #[test]
    fn each_reference_reads_its_set_and_set_1_falls_back() {
        let (a, b) = (Vec2::new(0.25, 0.5), Vec2::new(0.75, 0.5));
        let set1 = TextureRef { uv_set: 1, ..TextureRef::new(0) };
        let both = TexCoords { uv: [Some(a), Some(b)], footprint: [None, None] };
        assert_eq!(both.of(&TextureRef::new(0)).0, Some(a));
        assert_eq!(both.of(&set1).0, Some(b));
        let one = TexCoords::from(Some(a));
        assert_eq!(one.of(&set1).0, Some(a), "no set 1: set 0");
        assert_eq!(TexCoords::default().of(&set1).0, None);
    }

    #[test]
    fn the_coverage_follows_the_base_colour_or_alpha_texture() {
        let set1 = TextureRef { uv_set: 1, ..TextureRef::new(0) };
        let mut t = MaterialTextures::default();
        assert!(!t.reads_set1() && t.coverage_set() == 0);
        t.occlusion = Some(ScalarTexture { texture: set1, channel: Channel::Red, remap: None });
        assert!(t.reads_set1() && t.coverage_set() == 0);
        t.base_color = Some(set1);
        assert_eq!(t.coverage_set(), 1);
        t.alpha = Some(ScalarTexture { texture: TextureRef::new(0), channel: Channel::Alpha, remap: None });
        assert_eq!(t.coverage_set(), 0);
    }
}
