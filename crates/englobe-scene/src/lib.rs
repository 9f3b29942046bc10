//! # englobe-scene
//!
//! englobe's scene files: a small TOML format (documented key by key in `docs/scene-format.md`)
//! read into a validated [`Scene`], and the mesh files scenes name ([`mesh`]: OBJ + MTL, PLY,
//! glTF 2.0), and pbrt-v4 scenes ([`pbrt`]). A bad file is refused with an error that names the file, the line (or byte) and
//! says what was expected; nothing here panics on user input.

pub mod environment;
pub mod error;
pub mod format;
pub mod framing;
pub mod load_observer;
pub mod material;
pub mod material_eval;
pub mod mesh;
pub mod model;
pub mod numbers;
pub mod overrides;
pub mod parse;
mod parse_environment;
mod parse_material;
mod parse_mesh;
pub mod pbrt;
pub mod pixel_filter;
pub mod random_triangles;
pub mod shared_data;
pub mod tex_coords;
pub mod texture;

pub use environment::{Environment, EnvironmentMap, Sky};
pub use error::{Located, SceneError};
pub use load_observer::{LoadObserver, Unobserved};
pub use material::{
    Alpha, AlphaMode, Channel, MaterialModel, MaterialTextures, NormalEncoding, NormalMap, ScalarTexture, TextureRef,
    UvTransform,
};
pub use material_eval::{MISSING_TEXTURE_COLOR, SurfaceParams};
pub use model::{
    Camera, ImageSettings, IntegratorKind, Light, MAX_DEPTH, MAX_PIXELS, MAX_SAMPLES, Material, MaterialId,
    NoiseAllocation, OutputSettings, Projection, SamplerKind, Scene, SceneObject, TextureFilter, ToneMap,
};
pub use overrides::Override;
pub use parse::{
    DEFAULT_MATERIAL, load_scene, load_scene_observed, load_scene_with, parse_scene, parse_scene_observed,
    parse_scene_with,
};
pub use parse_mesh::MAX_MESH_INSTANCES;
pub use pixel_filter::PixelFilter;
pub use random_triangles::MAX_RANDOM_TRIANGLES;
pub use tex_coords::TexCoords;
pub use texture::{ColorSpace, Sampler, Texture, TextureId, Wrap};
