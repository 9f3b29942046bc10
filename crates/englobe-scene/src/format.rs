//! The scene file as written: serde structures mirroring the TOML, documented key by key in
//! `docs/scene-format.md`. Every table refuses unknown keys, and every number is checked as it is
//! read (see [`crate::numbers`]) so that errors point at the offending value.

use std::collections::BTreeMap;

use serde::Deserialize;
use toml::Spanned;

use crate::numbers::{Color, Finite, Fraction, Matrix, NonNegative, Point, Positive, Scale};

/// A whole scene file.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SceneFile {
    pub image: Spanned<ImageDef>,
    pub camera: Spanned<CameraDef>,
    #[serde(default)]
    pub materials: BTreeMap<String, Spanned<MaterialDef>>,
    #[serde(default)]
    pub point_light: Vec<PointLightDef>,
    #[serde(default)]
    pub directional_light: Vec<DirectionalLightDef>,
    #[serde(default)]
    pub sphere: Vec<SphereDef>,
    #[serde(default)]
    pub sphere_grid: Vec<Spanned<SphereGridDef>>,
    #[serde(default)]
    pub plane: Vec<PlaneDef>,
    #[serde(default, rename = "box")]
    pub boxes: Vec<Spanned<BoxDef>>,
    #[serde(default)]
    pub triangle: Vec<Spanned<TriangleDef>>,
    #[serde(default)]
    pub random_triangles: Vec<Spanned<RandomTrianglesDef>>,
    #[serde(default)]
    pub mesh: Vec<Spanned<MeshDef>>,
    #[serde(default)]
    pub rectangle: Vec<Spanned<RectangleDef>>,
    pub environment: Option<Spanned<EnvironmentDef>>,
}

fn one() -> u32 {
    1
}
fn five() -> u32 {
    5
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ImageDef {
    pub width: Spanned<u32>,
    pub height: Spanned<u32>,
    #[serde(default = "one")]
    pub samples: u32,
    #[serde(default = "five")]
    pub max_depth: u32,
    pub min_contribution: Option<crate::numbers::Fraction>,
    pub noise_threshold: Option<crate::numbers::NonNegative>,
    pub min_samples: Option<Spanned<u32>>,
    #[serde(default)]
    pub noise_allocation: crate::model::NoiseAllocation,
    pub background: Option<Color>,
    pub ambient: Option<Color>,
    #[serde(default)]
    pub seed: u64,
    #[serde(default)]
    pub sampler: crate::model::SamplerKind,
    #[serde(default)]
    pub integrator: crate::model::IntegratorKind,
    pub exposure: Option<Spanned<Finite>>,
    #[serde(default)]
    pub tonemap: crate::model::ToneMap,
    #[serde(default)]
    pub exr_half: bool,
    pub clamp: Option<Positive>,
    pub filter: Option<Spanned<String>>,
    pub filter_radius: Option<Spanned<FilterRadius>>,
    pub filter_sigma: Option<Spanned<Positive>>,
    #[serde(default)]
    pub texture_filter: crate::model::TextureFilter,
}

/// A filter radius: one number for both axes, or `[x, y]`.
#[derive(Clone, Copy, Debug, Deserialize)]
#[serde(untagged)]
pub enum FilterRadius {
    One(f64),
    Two([f64; 2]),
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CameraDef {
    pub position: Point,
    pub look_at: Spanned<Point>,
    pub up: Option<Spanned<Point>>,
    pub fov: Option<Spanned<Finite>>,
    #[serde(default)]
    pub projection: ProjectionKind,
    pub view_height: Option<Spanned<Positive>>,
    pub aperture: Option<NonNegative>,
    pub focus_distance: Option<Positive>,
}

/// The camera's `projection`.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum ProjectionKind {
    #[default]
    Perspective,
    Orthographic,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MaterialDef {
    pub model: Option<MaterialModelKind>,
    pub diffuse: Option<Spanned<Color>>,
    pub base_color: Option<Spanned<Color>>,
    pub specular: Option<Color>,
    pub shininess: Option<NonNegative>,
    pub reflectivity: Option<Fraction>,
    pub transparency: Option<Fraction>,
    pub ior: Option<Positive>,
    pub emission: Option<Color>,
    pub emission_strength: Option<NonNegative>,
    pub metallic: Option<Spanned<Fraction>>,
    pub roughness: Option<Spanned<Fraction>>,
    pub transmission: Option<Spanned<Fraction>>,
    pub base_color_texture: Option<Spanned<String>>,
    pub metallic_roughness_texture: Option<Spanned<String>>,
    pub normal_texture: Option<Spanned<String>>,
    pub normal_scale: Option<Finite>,
    pub emission_texture: Option<Spanned<String>>,
    pub texture_wrap: Option<WrapKind>,
    pub double_sided: Option<bool>,
    pub alpha: Option<Fraction>,
    pub alpha_mode: Option<AlphaModeKind>,
    pub alpha_cutoff: Option<Spanned<Fraction>>,
}

/// A material's `model`.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum MaterialModelKind {
    #[default]
    Classic,
    MetallicRoughness,
}

/// A material's `alpha_mode`.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum AlphaModeKind {
    #[default]
    Opaque,
    Mask,
    Blend,
}

/// A material's `texture_wrap`.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum WrapKind {
    #[default]
    Repeat,
    MirroredRepeat,
    ClampToEdge,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PointLightDef {
    pub position: Point,
    pub color: Option<Color>,
    pub intensity: Option<NonNegative>,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct DirectionalLightDef {
    pub direction: Spanned<Point>,
    pub color: Option<Color>,
    pub intensity: Option<NonNegative>,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SphereDef {
    pub center: Point,
    pub radius: Positive,
    pub material: Option<Spanned<String>>,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SphereGridDef {
    pub origin: Point,
    pub spacing: Point,
    pub counts: [u32; 3],
    pub radius: Positive,
    pub material: Option<Spanned<String>>,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PlaneDef {
    pub point: Point,
    pub normal: Spanned<Point>,
    pub material: Option<Spanned<String>>,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BoxDef {
    pub min: Point,
    pub max: Point,
    pub material: Option<Spanned<String>>,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TriangleDef {
    pub vertices: [Point; 3],
    pub material: Option<Spanned<String>>,
}

/// A box filled with random triangles (see `crate::random_triangles`).
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RandomTrianglesDef {
    pub count: Spanned<u32>,
    pub min: Point,
    pub max: Point,
    pub size: Positive,
    #[serde(default)]
    pub seed: u64,
    pub material: Option<Spanned<String>>,
}

/// A mesh file placed in the scene, once or many times.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MeshDef {
    pub path: Spanned<String>,
    pub translate: Option<Point>,
    pub rotate: Option<Point>,
    pub scale: Option<Scale>,
    pub matrix: Option<Matrix>,
    pub material: Option<Spanned<String>>,
    pub smooth_angle: Option<Spanned<Finite>>,
    pub instances: Option<Vec<Spanned<TransformDef>>>,
    pub grid: Option<Spanned<GridDef>>,
}

/// A placement: translate, rotate (degrees), scale, or a 4x4 matrix.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TransformDef {
    pub translate: Option<Point>,
    pub rotate: Option<Point>,
    pub scale: Option<Scale>,
    pub matrix: Option<Matrix>,
}

/// Instances on a regular grid.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct GridDef {
    pub counts: [u32; 3],
    pub spacing: Point,
    pub origin: Option<Point>,
    pub rotate_step: Option<Point>,
}

/// A parallelogram (two triangles): `corner`, `corner + edge1`, `corner + edge1 + edge2`,
/// `corner + edge2`, facing `edge1 x edge2`.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RectangleDef {
    pub corner: Point,
    pub edge1: Point,
    pub edge2: Point,
    pub material: Option<Spanned<String>>,
}

/// The `[environment]` table: exactly one of `file`, `color`, or `zenith` with `horizon`.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct EnvironmentDef {
    pub file: Option<Spanned<String>>,
    pub color: Option<Spanned<Color>>,
    pub zenith: Option<Spanned<Color>>,
    pub horizon: Option<Spanned<Color>>,
    pub ground: Option<Spanned<Color>>,
    pub intensity: Option<NonNegative>,
    pub rotation: Option<Finite>,
}
