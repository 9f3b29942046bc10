//! Progress on standard error, shown only when it is a terminal and not asked to be quiet: a
//! spinner and then one line per phase before the render (loading the scene and its meshes,
//! building the structure, each with its counts and time), and a bar counting tiles. Shown only
//! on a terminal so that logs and pipes get the results alone.

use std::io::IsTerminal;
use std::time::{Duration, Instant};

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
        Phase { spinner, start: Instant::now() }
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
