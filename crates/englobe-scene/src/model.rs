//! The validated scene, as the renderer receives it. Everything here has been checked: sizes are
//! within limits, numbers are finite, the camera is not degenerate and every object's material
//! exists.

use std::sync::Arc;

use englobe::{Object, TriangleMesh, Vec2, Vec3};
use glam::Vec4;

pub use crate::material::Material;
use crate::tex_coords::TexCoords;
use crate::texture::Texture;

/// Name of the material objects get when they name none.
pub const DEFAULT_MATERIAL: &str = "default";

/// Largest image, in pixels (2^28: a 16384 x 16384 image), refused before anything is allocated.
pub const MAX_PIXELS: u64 = 1 << 28;
/// Most samples per pixel.
pub const MAX_SAMPLES: u32 = 1 << 16;
/// Deepest recursion of secondary rays (pbrt scenes ask for up to 65 and more; Russian roulette
/// ends most paths well before).
pub const MAX_DEPTH: u32 = 128;

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
    /// How adaptive sampling shares the samples among blocks: every block down to the
    /// threshold, or as many as lower the image's squared error most.
    pub noise_allocation: NoiseAllocation,
    /// Colour of rays that hit nothing (linear RGB).
    pub background: Vec3,
    /// Light that reaches every point, scaled by the diffuse colour (the classic ambient term).
    pub ambient: Vec3,
    /// Seed of the pixel sampler; the same seed gives the same image.
    pub seed: u64,
    /// Where the pixel sampler's numbers come from.
    pub sampler: SamplerKind,
    /// How light is computed.
    pub integrator: IntegratorKind,
    /// Which samples a pixel averages (with more than one sample per pixel): the box of radius
    /// 0.5 by default, samples uniform over the pixel.
    pub filter: crate::pixel_filter::PixelFilter,
    /// Largest component a sample's radiance may have (against fireflies): a sample above it is
    /// scaled down to it, keeping its hue; `None` (the default) leaves samples as they are.
    /// It changes the pixels, so tiles' digests cover it.
    pub clamp: Option<f32>,
    /// How the linear image is written (exposure and tone map for PNG, half floats for EXR):
    /// no pixel value depends on it, so tiles' digests leave it out.
    pub output: OutputSettings,
    /// How textures are read at a ray's hit: at the point, or over the footprint of the ray's
    /// cone (englobe-render's `ray_cone`).
    pub texture_filter: TextureFilter,
}

/// How adaptive sampling shares its samples among the blocks of pixels (englobe-render's
/// `adaptive`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Deserialize, serde::Serialize)]
#[serde(rename_all = "lowercase")]
pub enum NoiseAllocation {
    /// Every block samples until its estimated error falls under the threshold, as Cycles and
    /// RenderMan do: the noise looks even over the image. A block with `k` times the noise of
    /// another takes `k^2` times its samples.
    #[default]
    Even,
    /// A block stops once one more sample would lower the image's squared error less than it
    /// would for a block at the threshold after the first pass: a block with `k` times the noise
    /// of another takes `k` times its samples, the split of a budget that minimises the image's
    /// mean squared error. Noisy regions end noisier than the threshold, quiet ones as `even`.
    Mse,
}

impl NoiseAllocation {
    /// The name used in scene files.
    pub fn name(self) -> &'static str {
        match self {
            NoiseAllocation::Even => "even",
            NoiseAllocation::Mse => "mse",
        }
    }
}

/// How textures are read where a ray hits them.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Deserialize, serde::Serialize)]
#[serde(rename_all = "lowercase")]
pub enum TextureFilter {
    /// At the hit point (bilinear): far textures alias unless many samples per pixel average
    /// them.
    None,
    /// Over the footprint of the ray's cone, from a mip pyramid (Amanatides 1984; Akenine-Möller
    /// et al. 2019): trilinear, anisotropic by footprint assembly. The default: on the textured
    /// ground of `englobe experiment fewer-rays`, one sample per pixel with cones is as close
    /// to the converged image as 40 without (docs/fewer-rays.md).
    #[default]
    Cone,
}

impl TextureFilter {
    /// The name used in scene files and on the command line.
    pub fn name(self) -> &'static str {
        match self {
            TextureFilter::None => "none",
            TextureFilter::Cone => "cone",
        }
    }
}

/// How a linear image becomes a file.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct OutputSettings {
    /// Exposure in stops (EV): PNG values are multiplied by `2^exposure` before the tone map.
    pub exposure: f32,
    /// The curve from exposed linear values to display values, for PNG.
    pub tonemap: ToneMap,
    /// OpenEXR output in 16-bit half floats instead of 32-bit floats.
    pub exr_half: bool,
}

/// Largest exposure, in stops, either way.
pub const MAX_EXPOSURE: f32 = 64.0;

/// A tone map: how exposed linear radiance becomes a display value in `0..=1` (before sRGB).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Deserialize, serde::Serialize)]
#[serde(rename_all = "lowercase")]
pub enum ToneMap {
    /// Values are clipped to `0..=1` (englobe's images before tone maps existed).
    #[default]
    None,
    /// An ACES-like filmic curve (Narkowicz 2016's fit of the ACES RRT and ODT).
    Filmic,
}

impl ToneMap {
    /// The name used in scene files and on the command line.
    pub fn name(self) -> &'static str {
        match self {
            ToneMap::None => "none",
            ToneMap::Filmic => "filmic",
        }
    }
}

/// Where a pixel's random numbers come from (see englobe-render's `sampler`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Deserialize, serde::Serialize)]
#[serde(rename_all = "lowercase")]
pub enum SamplerKind {
    /// Independent uniform numbers (a PCG32 stream per pixel).
    #[default]
    Independent,
    /// Owen-scrambled Sobol points padded in groups of four dimensions (Burley 2020).
    Sobol,
}

impl SamplerKind {
    /// The name used in scene files.
    pub fn name(self) -> &'static str {
        match self {
            SamplerKind::Independent => "independent",
            SamplerKind::Sobol => "sobol",
        }
    }
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
    /// The image's right is `up x forward` (pbrt's camera space, left-handed) instead of
    /// englobe's `forward x up`: set by the pbrt loader, so that pbrt scenes are not mirrored.
    pub left_handed: bool,
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
            left_handed: false,
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
    /// For meshes: one tangent per vertex of the mesh (of the instanced mesh for an instance,
    /// in its own space), shared by instances: `xyz` the unit tangent along increasing `u` (of
    /// the texture coordinate set the triangle's normal map reads), `w` the handedness (`±1`),
    /// the bitangent being `w * cross(normal, tangent)`, which points towards decreasing `v`
    /// (the top of the image: glTF 2.0's `TANGENT` convention, and
    /// MikkTSpace's on coordinates with `v` up). Present when the file gives tangents or a
    /// material of the mesh has a normal map (then generated with MikkTSpace).
    pub tangents: Option<Arc<[Vec4]>>,
}

impl SceneObject {
    /// An object with one material.
    pub fn new(object: Object, material: MaterialId) -> Self {
        SceneObject { object, material, triangle_materials: None, tangents: None }
    }

    /// The mesh of a mesh or instance (in its own space for an instance).
    fn mesh(&self) -> Option<&TriangleMesh> {
        match &self.object {
            Object::Mesh(m) => Some(m),
            Object::Instance(i) => Some(i.mesh()),
            Object::Shape(_) => None,
        }
    }

    /// The corners of triangle `prim` and their weights at barycentric `(u, v)`, the convention
    /// of englobe's hits (`PrimHit`, `WorldHit`): the point is `(1 - u - v) * p0 + u * p1 + v * p2`
    /// for the triangle's vertices `[p0, p1, p2]` in file order.
    fn corners(&self, prim: u32, u: f32, v: f32) -> Option<([u32; 3], [f32; 3])> {
        let tri = *self.mesh()?.triangles().get(prim as usize)?;
        Some((tri, [1.0 - u - v, u, v]))
    }

    /// The texture coordinate (set 0, glTF convention: `(0, 0)` the image's top-left corner, `v`
    /// down; OBJ and PLY coordinates were flipped when read) at barycentric `(u, v)` of triangle
    /// `prim`, interpolated from the vertices; `None` for shapes and meshes without coordinates.
    pub fn uv(&self, prim: u32, u: f32, v: f32) -> Option<Vec2> {
        self.uv_in(0, prim, u, v)
    }

    /// [`SceneObject::uv`] in texture coordinate set `set` (0 or 1); `None` where the mesh has
    /// no such set (no fallback here: see [`TexCoords`]).
    pub fn uv_in(&self, set: u32, prim: u32, u: f32, v: f32) -> Option<Vec2> {
        let uvs = self.mesh()?.uv_set(set)?;
        let (tri, w) = self.corners(prim, u, v)?;
        Some(uvs[tri[0] as usize] * w[0] + uvs[tri[1] as usize] * w[1] + uvs[tri[2] as usize] * w[2])
    }

    /// The texture coordinates at barycentric `(u, v)` of triangle `prim` in set 0, and in set 1
    /// when `set1` asks for it (a material reads it there) and the mesh has it; no footprints.
    pub fn tex_coords(&self, set1: bool, prim: u32, u: f32, v: f32) -> TexCoords {
        let second = if set1 { self.uv_in(1, prim, u, v) } else { None };
        TexCoords { uv: [self.uv(prim, u, v), second], footprint: [None, None] }
    }

    /// The tangent at barycentric `(u, v)` of triangle `prim` (see [`SceneObject::tangents`]):
    /// `xyz` interpolated and normalised, in the mesh's own space (an instance's renderer moves
    /// it by the instance's matrix, not its inverse transpose, and flips `w` when the matrix
    /// mirrors), `w` the first corner's handedness. `None` without tangents or when the
    /// interpolated tangent vanishes.
    pub fn tangent(&self, prim: u32, u: f32, v: f32) -> Option<Vec4> {
        let tangents = self.tangents.as_ref()?;
        let (tri, w) = self.corners(prim, u, v)?;
        let t = |k: usize| tangents.get(tri[k] as usize).copied();
        let (a, b, c) = (t(0)?, t(1)?, t(2)?);
        let xyz = (a.truncate() * w[0] + b.truncate() * w[1] + c.truncate() * w[2]).try_normalize()?;
        Some(xyz.extend(if a.w < 0.0 { -1.0 } else { 1.0 }))
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
    /// Textures, indexed by [`crate::TextureId`] ([`crate::TextureRef::texture`]); each image
    /// is decoded once and shared. A texture whose file could not be read is here too, without
    /// an image (see [`Texture::error`]), and a warning says so.
    pub textures: Vec<Arc<Texture>>,
    /// Objects.
    pub objects: Vec<SceneObject>,
    /// The light from infinitely far away that escaping rays see (replaces the image's
    /// `background`), if the scene has an `[environment]`.
    pub environment: Option<crate::environment::Environment>,
    /// What was skipped or repaired while loading (from mesh files, mostly), for the user.
    pub warnings: Vec<String>,
}
