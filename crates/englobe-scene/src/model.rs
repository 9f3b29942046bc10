//! The validated scene, as the renderer receives it. Everything here has been checked: sizes are
//! within limits, numbers are finite, the camera is not degenerate and every object's material
//! exists.

use std::sync::Arc;

use englobe::{Object, Vec3};

/// Largest image, in pixels (2^28: a 16384 x 16384 image), refused before anything is allocated.
pub const MAX_PIXELS: u64 = 1 << 28;
/// Most samples per pixel.
pub const MAX_SAMPLES: u32 = 1 << 16;
/// Deepest recursion of secondary rays.
pub const MAX_DEPTH: u32 = 64;

/// Image and integrator settings.
#[derive(Clone, Debug, PartialEq)]
pub struct ImageSettings {
    /// Width in pixels, at least 1.
    pub width: u32,
    /// Height in pixels, at least 1.
    pub height: u32,
    /// Samples per pixel: 1 shoots through pixel centres; more jitters them over the pixel.
    pub samples: u32,
    /// Maximum number of reflection/refraction bounces after the primary ray.
    pub max_depth: u32,
    /// Adaptive depth (Hall and Greenberg 1983): a reflected or refracted ray is cast only while
    /// its contribution to the pixel, the product of the reflection and transmission factors
    /// along its path, is at least this; 0 (the default) casts every ray up to `max_depth`.
    pub min_contribution: f32,
    /// Adaptive sampling (see englobe-render's `adaptive`): above 0, every 8 x 8 block of pixels
    /// stops taking samples once its estimated relative error falls under this, and `samples` is
    /// the most a pixel takes; 0 (the default) takes `samples` everywhere.
    pub noise_threshold: f32,
    /// Samples of adaptive sampling's first pass, before any block may stop (`None`: as Cycles
    /// chooses them, `16 / noise_threshold^0.3`); at most `samples`.
    pub min_samples: Option<u32>,
    /// Colour of rays that hit nothing (linear RGB).
    pub background: Vec3,
    /// Light that reaches every point, scaled by the diffuse colour (the classic ambient term).
    pub ambient: Vec3,
    /// Seed of the pixel sampler; the same seed gives the same image.
    pub seed: u64,
    /// How light is computed.
    pub integrator: IntegratorKind,
}

/// The light transport algorithm.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Deserialize, serde::Serialize)]
#[serde(rename_all = "lowercase")]
pub enum IntegratorKind {
    /// Whitted's recursion (the seed's): shadow rays, mirror and refraction rays, an ambient term.
    #[default]
    Whitted,
    /// Monte Carlo path tracing: diffuse inter-reflection and emissive surfaces as lights.
    Path,
}

impl IntegratorKind {
    /// The name used in scene files and on the command line.
    pub fn name(self) -> &'static str {
        match self {
            IntegratorKind::Whitted => "whitted",
            IntegratorKind::Path => "path",
        }
    }
}

impl ImageSettings {
    /// Checks the size, sample count and depth against the limits above.
    pub fn check_limits(width: u32, height: u32, samples: u32, max_depth: u32) -> Result<(), String> {
        if width == 0 || height == 0 {
            return Err(format!("image size {width}x{height}: width and height must be at least 1"));
        }
        let pixels = width as u64 * height as u64;
        if pixels > MAX_PIXELS {
            return Err(format!("image size {width}x{height} is {pixels} pixels, more than the limit of {MAX_PIXELS}"));
        }
        if samples == 0 || samples > MAX_SAMPLES {
            return Err(format!("{samples} samples per pixel: expected 1 to {MAX_SAMPLES}"));
        }
        if max_depth > MAX_DEPTH {
            return Err(format!("maximum depth {max_depth}: expected 0 to {MAX_DEPTH}"));
        }
        Ok(())
    }
}

/// A camera: perspective or orthographic, a pinhole or a thin lens.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Camera {
    /// Eye position (for an orthographic camera, the centre of the plane rays start from).
    pub position: Vec3,
    /// Point the camera looks at (distinct from `position`).
    pub look_at: Vec3,
    /// Up direction (not parallel to the view direction).
    pub up: Vec3,
    /// Vertical field of view, in degrees, in `(0, 180)` (perspective).
    pub fov_degrees: f32,
    /// How points are projected onto the image.
    pub projection: Projection,
    /// Radius of the thin lens; 0 is a pinhole (everything sharp).
    pub lens_radius: f32,
    /// Distance along the view direction of the plane in focus (positive).
    pub focus_distance: f32,
}

impl Camera {
    /// A pinhole perspective camera.
    pub fn pinhole(position: Vec3, look_at: Vec3, up: Vec3, fov_degrees: f32) -> Self {
        Camera {
            position,
            look_at,
            up,
            fov_degrees,
            projection: Projection::Perspective,
            lens_radius: 0.0,
            focus_distance: (look_at - position).length(),
        }
    }
}

/// How a camera projects the scene.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Projection {
    /// Rays from the eye through the image plane: far things look smaller.
    Perspective,
    /// Parallel rays along the view direction: sizes do not depend on distance.
    Orthographic {
        /// Height of the view, in scene units (the width follows the image's aspect ratio).
        view_height: f32,
    },
}

/// A light source.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Light {
    /// Light from one point, falling off with the square of the distance.
    Point {
        /// Position.
        position: Vec3,
        /// Colour times intensity (linear RGB).
        power: Vec3,
    },
    /// Parallel light from infinitely far away, such as the sun.
    Directional {
        /// Unit direction the light travels in.
        direction: Vec3,
        /// Colour times intensity.
        radiance: Vec3,
    },
}

/// Surface appearance: a Phong-style local model plus Whitted's mirror and glass terms.
#[derive(Clone, Debug, PartialEq)]
pub struct Material {
    /// Diffuse (Lambert) colour.
    pub diffuse: Vec3,
    /// Specular highlight colour (Blinn-Phong).
    pub specular: Vec3,
    /// Blinn-Phong exponent.
    pub shininess: f32,
    /// Fraction of light mirrored, in `0..=1`.
    pub reflectivity: f32,
    /// Fraction of light transmitted, in `0..=1`; `reflectivity + transparency <= 1`.
    pub transparency: f32,
    /// Index of refraction of the inside of a transparent object.
    pub ior: f32,
    /// Light emitted by the surface itself.
    pub emission: Vec3,
}

impl Default for Material {
    /// A matte light grey.
    fn default() -> Self {
        Material {
            diffuse: Vec3::splat(0.7),
            specular: Vec3::ZERO,
            shininess: 32.0,
            reflectivity: 0.0,
            transparency: 0.0,
            ior: 1.5,
            emission: Vec3::ZERO,
        }
    }
}

/// Index into [`Scene::materials`].
pub type MaterialId = u32;

/// An object of the scene with its appearance.
#[derive(Clone, Debug, PartialEq)]
pub struct SceneObject {
    /// The geometry.
    pub object: Object,
    /// Its material.
    pub material: MaterialId,
    /// For meshes whose file gives each triangle a material (OBJ with several, glTF): one id per
    /// triangle of the mesh (of the instanced mesh for an instance), which replaces `material`.
    /// Instances of one mesh share the array.
    pub triangle_materials: Option<Arc<[MaterialId]>>,
}

impl SceneObject {
    /// An object with one material.
    pub fn new(object: Object, material: MaterialId) -> Self {
        SceneObject { object, material, triangle_materials: None }
    }

    /// The material of primitive `prim` of the object (the triangle of a mesh or instance).
    #[inline]
    pub fn material_of(&self, prim: u32) -> MaterialId {
        match &self.triangle_materials {
            Some(ids) => ids.get(prim as usize).copied().unwrap_or(self.material),
            None => self.material,
        }
    }
}

/// A complete, validated scene.
#[derive(Clone, Debug, PartialEq)]
pub struct Scene {
    /// Image and integrator settings.
    pub image: ImageSettings,
    /// The camera.
    pub camera: Camera,
    /// Light sources.
    pub lights: Vec<Light>,
    /// Materials, indexed by [`MaterialId`].
    pub materials: Vec<Material>,
    /// Material names, parallel to `materials`.
    pub material_names: Vec<String>,
    /// Objects.
    pub objects: Vec<SceneObject>,
    /// What was skipped or repaired while loading (from mesh files, mostly), for the user.
    pub warnings: Vec<String>,
}
