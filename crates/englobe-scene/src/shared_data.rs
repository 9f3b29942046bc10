//! Finding the shared scene data (real meshes kept beside the repository, never inside it), for
//! tests, examples and benchmarks.

use std::path::{Path, PathBuf};

/// Environment variable that names the shared data folder (the one holding `scenes/`).
pub const SHARED_ENV: &str = "ENGLOBE_SHARED";

/// The shared data folder: `$ENGLOBE_SHARED` if set, otherwise the first `shared/` folder holding
/// a `scenes/` directory beside `start` or one of its ancestors.
pub fn locate_shared(start: &Path) -> Option<PathBuf> {
    if let Some(dir) = std::env::var_os(SHARED_ENV) {
        let dir = PathBuf::from(dir);
        return dir.join("scenes").is_dir().then_some(dir);
    }
    start.ancestors().map(|a| a.join("shared")).find(|s| s.join("scenes").is_dir())
}

/// The shared `scenes/meshes` folder, or a panic that says where it was looked for: tests that
/// need it must fail loudly where it is missing, not pass by skipping.
pub fn shared_meshes_or_panic(start: &Path) -> PathBuf {
    match locate_shared(start) {
        Some(dir) => dir.join("scenes").join("meshes"),
        None => panic!(
            "the shared scene data was not found: set {SHARED_ENV} to the folder holding `scenes/`, or put it \
             at `shared/` beside {} or one of its parents",
            start.display()
        ),
    }
}
