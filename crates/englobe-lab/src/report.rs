//! Reports for people and for programs: what a render counted (the table of `--stats`, the JSON
//! of `--stats-json`), any report written as JSON, and numbers written the way the tables write
//! them (digits in groups of three, bytes in binary units).

use std::path::Path;

use englobe_render::{KindStats, RayKind, RenderStats};
use serde::Serialize;

use crate::error::LabError;

/// Everything `--stats-json` writes.
#[derive(Serialize)]
pub struct StatsReport<'a> {
    /// The scene's file, or `default`.
    pub scene: &'a str,
    /// The structure's name.
    pub accel: &'a str,
    /// Image width.
    pub width: u32,
    /// Image height.
    pub height: u32,
    /// Samples per pixel (with adaptive sampling: the most any pixel took).
    pub samples: u32,
    /// Samples taken over the whole image (or window).
    pub samples_total: u64,
    /// Samples per pixel on average.
    pub samples_mean: f64,
    /// The noise threshold of adaptive sampling, if it was on.
    pub noise_threshold: Option<f32>,
    /// Seconds to build the world.
    pub build_seconds: f64,
    /// Seconds to render.
    pub render_seconds: f64,
    /// Triangles in the picture (every instance counting its mesh's).
    pub triangles: usize,
    /// Peak resident memory of the process, where the system reports it.
    pub peak_memory_bytes: Option<u64>,
    /// One row per kind of ray.
    pub kinds: Vec<KindRow>,
    /// All kinds together.
    pub total: KindStats,
}

/// What the rays of one kind counted.
#[derive(Serialize)]
pub struct KindRow {
    /// The kind of ray.
    pub kind: RayKind,
    /// Its counts.
    #[serde(flatten)]
    pub stats: KindStats,
}

impl<'a> StatsReport<'a> {
    /// The rows of `stats`, one per kind of ray, in [`RayKind::ALL`]'s order.
    pub fn rows(stats: &RenderStats) -> Vec<KindRow> {
        RayKind::ALL.iter().map(|&kind| KindRow { kind, stats: *stats.kind(kind) }).collect()
    }
}

/// The table `--stats` prints.
pub fn stats_table(stats: &RenderStats) -> String {
    let mut out = format!(
        "{:<10} {:>14} {:>16} {:>10} {:>16} {:>16}\n",
        "ray kind", "rays", "exact tests", "tests/ray", "nodes visited", "box tests"
    );
    let line = |name: &str, k: &KindStats| {
        let per_ray = if k.rays == 0 { 0.0 } else { k.exact_tests as f64 / k.rays as f64 };
        format!(
            "{:<10} {:>14} {:>16} {:>10.2} {:>16} {:>16}\n",
            name, k.rays, k.exact_tests, per_ray, k.nodes_visited, k.box_tests
        )
    };
    for kind in RayKind::ALL {
        out += &line(kind.name(), stats.kind(kind));
    }
    out += &line("total", &stats.total());
    out
}

/// Writes `value` as pretty JSON to `path`, atomically.
pub fn write_json(path: &Path, value: &impl Serialize) -> Result<(), LabError> {
    let text = serde_json::to_string_pretty(value).map_err(LabError::Serialise)?;
    englobe_render::output::write_atomically(path, |w| {
        use std::io::Write;
        w.write_all(text.as_bytes())
            .and_then(|_| w.write_all(b"\n"))
            .map_err(|error| englobe_render::OutputError::Io { path: path.to_owned(), error })
    })?;
    Ok(())
}

/// `n` with its digits in groups of three separated by spaces, as the seed report writes them
/// (`422 762`).
pub fn grouped(n: u64) -> String {
    let digits = n.to_string();
    let mut out = String::with_capacity(digits.len() + digits.len() / 3);
    for (i, c) in digits.chars().enumerate() {
        if i > 0 && (digits.len() - i).is_multiple_of(3) {
            out.push(' ');
        }
        out.push(c);
    }
    out
}

/// A byte count in B, KiB, MiB or GiB.
pub fn bytes(n: usize) -> String {
    const UNITS: [&str; 4] = ["B", "KiB", "MiB", "GiB"];
    let mut value = n as f64;
    let mut unit = 0;
    while value >= 1024.0 && unit + 1 < UNITS.len() {
        value /= 1024.0;
        unit += 1;
    }
    if unit == 0 { format!("{n} B") } else { format!("{value:.1} {}", UNITS[unit]) }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn digit_groups() {
        assert_eq!(grouped(0), "0");
        assert_eq!(grouped(999), "999");
        assert_eq!(grouped(1000), "1 000");
        assert_eq!(grouped(422_762), "422 762");
        assert_eq!(grouped(25_197_800), "25 197 800");
    }

    #[test]
    fn byte_units() {
        assert_eq!(bytes(512), "512 B");
        assert_eq!(bytes(2048), "2.0 KiB");
        assert_eq!(bytes(3 << 20), "3.0 MiB");
    }
}
