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
    pub background: Option<Color>,
    pub ambient: Option<Color>,
    #[serde(default)]
    pub seed: u64,
    #[serde(default)]
    pub integrator: crate::model::IntegratorKind,
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
    pub diffuse: Option<Color>,
    pub specular: Option<Color>,
    pub shininess: Option<NonNegative>,
    pub reflectivity: Option<Fraction>,
    pub transparency: Option<Fraction>,
    pub ior: Option<Positive>,
    pub emission: Option<Color>,
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
