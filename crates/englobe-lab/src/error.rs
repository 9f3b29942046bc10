//! What can go wrong in an experiment or a comparison: a scene that does not parse, a structure
//! that cannot be built, a render refused, worker threads that do not start, a file not written.
//! Each error says what it was doing; the cause it wraps says why.

use std::path::PathBuf;

use englobe::{AccelKind, WorldError};
use englobe_render::{OutputError, RenderError};
use englobe_scene::SceneError;

/// An experiment or a comparison that could not finish.
#[derive(Debug, thiserror::Error)]
pub enum LabError {
    /// A scene of the experiment did not parse.
    #[error(transparent)]
    Scene(#[from] SceneError),
    /// The structure could not be built over the scene's objects.
    #[error("cannot build {kind}")]
    Build {
        /// The structure.
        kind: AccelKind,
        /// Why.
        #[source]
        source: WorldError,
    },
    /// The renderer refused the settings.
    #[error(transparent)]
    Render(#[from] RenderError),
    /// The worker threads did not start.
    #[error("cannot start the worker threads")]
    Threads(#[source] rayon::ThreadPoolBuildError),
    /// The folder for the images could not be created.
    #[error("cannot create {}", path.display())]
    CreateDir {
        /// The folder.
        path: PathBuf,
        /// Why.
        #[source]
        source: std::io::Error,
    },
    /// An image or a JSON file could not be written.
    #[error(transparent)]
    Output(#[from] OutputError),
    /// The report could not be turned into JSON.
    #[error("cannot serialise the statistics")]
    Serialise(#[source] serde_json::Error),
    /// The plot could not be written.
    #[error("cannot write the plot {}", path.display())]
    Plot {
        /// The SVG file.
        path: PathBuf,
        /// Why.
        #[source]
        source: OutputError,
    },
}
