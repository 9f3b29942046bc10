//! Watching a scene load: a [`LoadObserver`] is told when each mesh file of the scene starts and
//! ends loading, so that a command line can show the phases of a long load while they happen
//! rather than one line once everything is done.

use std::path::Path;
use std::time::Duration;

/// Told of each mesh file a scene reads, in the order of the scene's `[[mesh]]` entries. A file
/// placed many times (with the same options) is read, and reported, once.
pub trait LoadObserver {
    /// `path` starts loading.
    fn mesh_started(&self, path: &Path) {
        let _ = path;
    }

    /// `path` has loaded: `triangles` triangles in `elapsed` (reading, checking, normals and
    /// tangents; not the placement of its copies).
    fn mesh_loaded(&self, path: &Path, triangles: usize, elapsed: Duration) {
        let _ = (path, triangles, elapsed);
    }
}

/// An observer that does nothing, for loads nobody watches.
pub struct Unobserved;

impl LoadObserver for Unobserved {}
