//! Progress on standard error, shown only when it is a terminal and not asked to be quiet: a
//! spinner and then one line per phase before the render (loading the scene, each of its mesh
//! files as it loads, building the structure, each with its counts and time), and a bar counting
//! tiles. Shown only on a terminal so that logs and pipes get the results alone.

use std::cell::Cell;
use std::io::IsTerminal;
use std::path::Path;
use std::time::{Duration, Instant};

use englobe_scene::LoadObserver;
use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};

/// A bar counting tiles, hidden when standard error is not a terminal or `quiet` is set.
pub fn tile_bar(total: usize, quiet: bool) -> ProgressBar {
    progress_bar(total, "tiles", quiet)
}

/// A bar counting `unit`s (tiles, passes), hidden when standard error is not a terminal or
/// `quiet` is set.
pub fn progress_bar(total: usize, unit: &str, quiet: bool) -> ProgressBar {
    let bar = ProgressBar::new(total as u64);
    if quiet || !std::io::stderr().is_terminal() {
        bar.set_draw_target(ProgressDrawTarget::hidden());
    }
    bar.set_style(
        ProgressStyle::with_template(&format!(
            "{{spinner}} rendering [{{bar:40}}] {{percent:>3}}% {{pos}}/{{len}} {unit}, {{elapsed}} (eta {{eta}})"
        ))
        .expect("the template is valid")
        .progress_chars("=> "),
    );
    bar
}

/// The phases before the render, each a spinner while it runs and a line when it ends.
pub struct Phases {
    shown: bool,
}

/// A phase in progress: its spinner and its start.
pub struct Phase {
    spinner: ProgressBar,
    start: Instant,
    message: String,
}

impl Phases {
    /// Phases shown on standard error when it is a terminal and `quiet` is not set.
    pub fn new(quiet: bool) -> Self {
        Phases { shown: !quiet && std::io::stderr().is_terminal() }
    }

    /// Starts the phase `what` ("loading scene.toml").
    pub fn begin(&self, what: &str) -> Phase {
        let spinner = if self.shown { ProgressBar::new_spinner() } else { ProgressBar::hidden() };
        spinner.set_style(ProgressStyle::with_template("{spinner} {msg} {elapsed}").expect("the template is valid"));
        spinner.set_message(what.to_owned());
        spinner.enable_steady_tick(Duration::from_millis(100));
        Phase { spinner, start: Instant::now(), message: what.to_owned() }
    }

    /// Ends `phase`, returning its seconds, and prints `line(seconds)`.
    pub fn end(&self, phase: Phase, line: impl FnOnce(f64) -> String) -> f64 {
        let seconds = phase.start.elapsed().as_secs_f64();
        phase.spinner.finish_and_clear();
        if self.shown {
            eprintln!("{}", line(seconds));
        }
        seconds
    }
}

/// The line that ends the phase of one mesh file: its name, triangles and seconds.
pub fn mesh_line(path: &Path, triangles: usize, seconds: f64) -> String {
    format!("  mesh {}: {triangles} triangles in {seconds:.2} s", path.display())
}

/// The mesh files of a scene shown as phases of their own inside the phase `phase` that loads the
/// scene: its spinner names the file being read, and a line ([`mesh_line`]) is printed above it
/// as each file ends, so a long load shows where it is.
pub struct MeshPhases<'a> {
    phase: &'a Phase,
    shown: bool,
    meshes: Cell<usize>,
}

impl<'a> MeshPhases<'a> {
    /// Mesh phases within `phase`, shown when `phases` are.
    pub fn new(phases: &Phases, phase: &'a Phase) -> Self {
        MeshPhases { phase, shown: phases.shown, meshes: Cell::new(0) }
    }

    /// How many mesh files have loaded.
    pub fn count(&self) -> usize {
        self.meshes.get()
    }
}

impl LoadObserver for MeshPhases<'_> {
    fn mesh_started(&self, path: &Path) {
        self.phase.spinner.set_message(format!("{}: mesh {}", self.phase.message, path.display()));
    }

    fn mesh_loaded(&self, path: &Path, triangles: usize, elapsed: Duration) {
        self.meshes.set(self.meshes.get() + 1);
        self.phase.spinner.set_message(self.phase.message.clone());
        if self.shown {
            // Printed above the spinner, which is drawn again below the line.
            self.phase.spinner.suspend(|| eprintln!("{}", mesh_line(path, triangles, elapsed.as_secs_f64())));
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn mesh_phases_count_files_and_name_them() {
        let phases = Phases::new(true);
        let phase = phases.begin("loading scene.toml");
        let meshes = MeshPhases::new(&phases, &phase);
        meshes.mesh_started(Path::new("a.obj"));
        assert_eq!(phase.spinner.message(), "loading scene.toml: mesh a.obj");
        meshes.mesh_loaded(Path::new("a.obj"), 12, Duration::from_millis(250));
        assert_eq!((meshes.count(), phase.spinner.message()), (1, "loading scene.toml".to_owned()));
        assert_eq!(mesh_line(Path::new("b/c.ply"), 69451, 0.254), "  mesh b/c.ply: 69451 triangles in 0.25 s");
    }
}
