//! The values that parameters resolve to, shared by the builder and the files that read
//! parameters: what a colour stands for, a texture's one value, and pbrt's default material.

use englobe::Vec3;

use crate::model::Material;

/// What a colour stands for, which decides its range and how spectra become RGB.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum Role {
    /// A reflectance or transmittance, in `0..=1`.
    Reflectance,
    /// A physical constant such as a conductor's `eta` and `k`: any value of at least 0.
    Unbounded,
    /// A light's spectrum: pbrt-v4 normalises it to luminance 1, except RGB values, which it
    /// keeps as they are (their illuminant is normalised, not their colour).
    Light,
}

/// A texture's one value.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) enum TexValue {
    Color(Vec3),
    Float(f64),
}

/// A texture as englobe keeps it.
#[derive(Clone, Debug)]
pub(super) struct Texture {
    /// Its value, when it has one.
    pub value: Option<TexValue>,
    pub class: String,
}

/// Key of a texture: pbrt-v4 keeps float and spectrum textures apart.
pub(super) fn key(name: &str, float: bool) -> String {
    format!("{}:{name}", if float { "float" } else { "spectrum" })
}

/// pbrt's material for shapes that name none: `diffuse` with reflectance 0.5.
pub(super) fn default_material() -> Material {
    Material { diffuse: Vec3::splat(0.5), ..Material::default() }
}
