//! pbrt-v4 scene files (`.pbrt`) read into englobe's [`Scene`], following pbrt-v4's file-format
//! documentation ("pbrt-v4 User's Guide: Input File Format") and its parser (`parser.cpp`,
//! `scene.cpp`, `lights.cpp`, `materials.cpp` of pbrt-v4), with pbrt-v3's older names where they
//! differ (`color`, `point`, `matte`, `plastic`, `Film "image"`, `TransformBegin`).
//!
//! What is read, what is approximated and what is reported is listed in `docs/pbrt.md`. In short:
//! transforms, attributes, includes and imports, object instancing, the perspective and
//! orthographic cameras, the film's size, the sample count, the path depth, box, triangle and
//! Gaussian pixel filters, triangle meshes (inline, PLY, bilinear patches), spheres, disks,
//! diffuse and dielectric materials exactly and the others by the nearest classic material,
//! point, distant, constant infinite and diffuse area lights in pbrt's units. Everything else
//! is reported once per kind, with the file, line and column of its first occurrence, in
//! [`Scene::warnings`], and skipped; with `strict`, the first such thing is an error instead.
//! A malformed file is an error at its file, line and column; nothing here panics on a file.
//!
//! Why not the `pbrt4` crate (0.2.0 on crates.io, read for this purpose): its errors carry no
//! place (no file, line or column), its tokenizer prints every token with `dbg!`, indexes the
//! text byte by byte in a way that panics on non-ASCII text, `Import`, `ActiveTransform` and
//! gzip files reach `todo!()` (a panic), includes have no cycle or depth guard, and it builds
//! against glam 0.24 where englobe uses 0.34. pbrt's tokenizer and parameter lists are small;
//! owning them is what makes every error located and every input safe.
//!
//! ```no_run
//! let scene = englobe_scene::pbrt::load("scene-v4.pbrt".as_ref(), false)?;
//! for warning in &scene.warnings {
//!     eprintln!("warning: {warning}");
//! }
//! # Ok::<(), englobe_scene::SceneError>(())
//! ```

mod builder;
mod color;
mod finish;
mod lexer;
mod lights;
mod materials;
mod objects;
mod options;
mod params;
mod parser;
mod report;
mod shapes;
mod source;
mod spectrum;
mod textures;
mod transform;
mod values;

use std::path::Path;

use crate::error::{Located, SceneError};
use crate::model::Scene;
use crate::overrides::Override;

pub use parser::MAX_INCLUDE_DEPTH;
pub use source::{MAX_PBRT_FILE_BYTES, MAX_PBRT_TOTAL_BYTES};

/// True if `path` names a pbrt scene (its extension is `.pbrt`, in any case).
pub fn is_pbrt_path(path: &Path) -> bool {
    path.extension().is_some_and(|e| e.eq_ignore_ascii_case("pbrt"))
}

/// Reads the pbrt scene `path` and the files it includes. With `strict`, anything englobe would
/// skip or approximate is an error at its place; otherwise it is reported in
/// [`Scene::warnings`].
pub fn load(path: &Path, strict: bool) -> Result<Scene, SceneError> {
    let text = source::read_text(path).map_err(|e| SceneError::io(path, e))?;
    parse_owned(text, path, strict)
}

/// Reads pbrt scene `text`, which `file` names in messages; relative file names in it are
/// resolved against `file`'s folder.
pub fn parse(text: &str, file: &Path, strict: bool) -> Result<Scene, SceneError> {
    parse_owned(text.to_owned(), file, strict)
}

fn parse_owned(text: String, file: &Path, strict: bool) -> Result<Scene, SceneError> {
    let mut sources = source::Sources::default();
    let id = sources.add(file.display().to_string(), file.to_owned(), text, None);
    let search_dir = file.parent().unwrap_or(Path::new("")).to_owned();
    let mut parser = parser::Parser::new(builder::Builder::new(sources, strict, search_dir), id);
    let result = parser.run().and_then(|()| parser.b.finish());
    result.map_err(|fail| parser.b.sources.error(fail))
}

/// Refuses command-line overrides (`-D`, and `--look-from`, `--look-at`, `--fov`, which are
/// overrides too): they change a TOML scene's document, which a pbrt scene does not have. The
/// image options (`--width`, `--height`, `--scale`, `--spp`, `--integrator`) apply to the loaded
/// scene and work with pbrt scenes.
pub fn refuse_overrides(overrides: &[Override]) -> Result<(), SceneError> {
    let Some(first) = overrides.first() else { return Ok(()) };
    Err(SceneError::Invalid(Located {
        file: first.to_string(),
        line: 1,
        column: 1,
        message: "scene overrides (-D, --look-from, --look-at, --fov) apply to englobe's TOML scenes, not to pbrt \
                  scenes; --width, --height, --scale, --spp and --integrator do apply"
            .into(),
        source_line: String::new(),
    }))
}
