//! A decoded image as textures keep it: four channels per texel in the file's own precision (8 or
//! 16 bits, or 32-bit floats), converted to linear floats only when a texel is fetched, so that
//! a 2048 x 2048 JPEG takes 16 MiB and not 64.

use glam::Vec4;

use super::srgb::{srgb_to_linear, srgb8_table};

/// How the colour channels of a texture encode their values. Alpha is always linear (glTF 2.0,
/// section 3.9.2: "the alpha channel, if present, is always linear").
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ColorSpace {
    /// sRGB-encoded colour (glTF's base colour and emissive textures, MTL's colour maps).
    Srgb,
    /// Plain numbers (metallic-roughness, normal, occlusion, alpha and bump maps).
    Linear,
}

/// The texels, row after row from the top of the image, red, green, blue and alpha each.
#[derive(Clone, PartialEq)]
pub enum Texels {
    /// 8 bits per channel.
    Rgba8(Vec<[u8; 4]>),
    /// 16 bits per channel.
    Rgba16(Vec<[u16; 4]>),
    /// Floats (already linear: sRGB is not applied to them).
    RgbaF32(Vec<[f32; 4]>),
}

/// A decoded image.
#[derive(Clone, PartialEq)]
pub struct TexelImage {
    width: u32,
    height: u32,
    /// Channels in the file (1 grey, 2 grey and alpha, 3 RGB, 4 RGBA); missing ones are filled
    /// as the `image` crate does (grey copied to RGB, alpha 1).
    channels: u8,
    texels: Texels,
    /// FNV-1a hash of the decoded texels: two images with equal hashes hold (almost certainly)
    /// the same picture, which is what a scene digest needs without hashing texels again.
    hash: u64,
}

impl std::fmt::Debug for TexelImage {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "TexelImage({}x{}, {} channels, hash {:016x})", self.width, self.height, self.channels, self.hash)
    }
}

impl TexelImage {
    /// An image of `width` x `height` texels; `None` when the sizes disagree or are zero.
    pub fn new(width: u32, height: u32, channels: u8, texels: Texels) -> Option<Self> {
        let n = match &texels {
            Texels::Rgba8(t) => t.len(),
            Texels::Rgba16(t) => t.len(),
            Texels::RgbaF32(t) => t.len(),
        };
        if width == 0 || height == 0 || n as u64 != width as u64 * height as u64 {
            return None;
        }
        let hash = fnv1a(&texels);
        Some(TexelImage { width, height, channels: channels.clamp(1, 4), texels, hash })
    }

    /// An 8-bit RGBA image from texels in rows from the top.
    pub fn from_rgba8(width: u32, height: u32, texels: Vec<[u8; 4]>) -> Option<Self> {
        Self::new(width, height, 4, Texels::Rgba8(texels))
    }

    /// Width in texels.
    pub fn width(&self) -> u32 {
        self.width
    }

    /// Height in texels.
    pub fn height(&self) -> u32 {
        self.height
    }

    /// Channels the file held.
    pub fn channels(&self) -> u8 {
        self.channels
    }

    /// Bits per channel as stored (8, 16 or 32).
    pub fn bits(&self) -> u32 {
        match self.texels {
            Texels::Rgba8(_) => 8,
            Texels::Rgba16(_) => 16,
            Texels::RgbaF32(_) => 32,
        }
    }

    /// Bytes the texels take.
    pub fn bytes(&self) -> usize {
        self.width as usize * self.height as usize * 4 * (self.bits() as usize / 8)
    }

    /// The texels' hash (see the field's documentation).
    pub fn hash(&self) -> u64 {
        self.hash
    }

    /// Texel `(x, y)` (column, row from the top) as linear RGBA, the colour channels decoded from
    /// `space`. The caller keeps `x < width` and `y < height`.
    #[inline]
    pub fn fetch(&self, x: u32, y: u32, space: ColorSpace) -> Vec4 {
        let i = y as usize * self.width as usize + x as usize;
        match &self.texels {
            Texels::Rgba8(t) => {
                let [r, g, b, a] = t[i];
                let alpha = a as f32 / 255.0;
                match space {
                    ColorSpace::Srgb => {
                        let lut = srgb8_table();
                        Vec4::new(lut[r as usize], lut[g as usize], lut[b as usize], alpha)
                    }
                    ColorSpace::Linear => Vec4::new(r as f32, g as f32, b as f32, a as f32) / 255.0,
                }
            }
            Texels::Rgba16(t) => {
                let v = Vec4::from(t[i].map(|c| c as f32 / 65535.0));
                match space {
                    ColorSpace::Srgb => Vec4::new(srgb_to_linear(v.x), srgb_to_linear(v.y), srgb_to_linear(v.z), v.w),
                    ColorSpace::Linear => v,
                }
            }
            Texels::RgbaF32(t) => Vec4::from(t[i]),
        }
    }
}

fn fnv1a(texels: &Texels) -> u64 {
    let mut h: u64 = 0xcbf2_9ce4_8422_2325;
    let mut eat = |bytes: &[u8]| {
        for &b in bytes {
            h ^= b as u64;
            h = h.wrapping_mul(0x0000_0100_0000_01b3);
        }
    };
    match texels {
        Texels::Rgba8(t) => t.iter().for_each(|p| eat(p)),
        Texels::Rgba16(t) => t.iter().for_each(|p| p.iter().for_each(|c| eat(&c.to_le_bytes()))),
        Texels::RgbaF32(t) => t.iter().for_each(|p| p.iter().for_each(|c| eat(&c.to_bits().to_le_bytes()))),
    }
    h
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fetch_decodes_srgb_colour_but_not_alpha() {
        let img = TexelImage::from_rgba8(2, 1, vec![[188, 0, 255, 128], [10, 20, 30, 255]]).unwrap();
        let s = img.fetch(0, 0, ColorSpace::Srgb);
        assert!((s.x - 0.5029).abs() < 1e-3 && s.y == 0.0 && (s.z - 1.0).abs() < 1e-6);
        assert!((s.w - 128.0 / 255.0).abs() < 1e-6, "alpha stays linear");
        let l = img.fetch(0, 0, ColorSpace::Linear);
        assert!((l - Vec4::new(188.0, 0.0, 255.0, 128.0) / 255.0).abs().max_element() < 1e-6);
        assert_eq!(img.fetch(1, 0, ColorSpace::Linear), Vec4::new(10.0, 20.0, 30.0, 255.0) / 255.0);
        assert!(TexelImage::from_rgba8(3, 1, vec![[0; 4]; 2]).is_none());
        assert!(TexelImage::from_rgba8(0, 0, vec![]).is_none());
    }
}
