//! What one run measures: one [`Measurement`] per scene, library, ray set, query and thread
//! count, with the ratios to Embree and to obvhs filled in once every library has run, and the
//! CSV they are written to (atomically: a temporary file in the same folder, then renamed).

use std::fmt::Write as _;
use std::io::Write as _;
use std::path::Path;

use anyhow::Context;

use crate::measure::Query;
use crate::rays::RaySetKind;
use crate::registry::LibraryKind;

/// One measured cell.
#[derive(Clone, Debug, PartialEq)]
pub struct Measurement {
    /// Scene name.
    pub scene: String,
    /// Triangles in the scene.
    pub triangles: usize,
    /// Library.
    pub library: LibraryKind,
    /// What exactly was measured (structure, settings, query functions).
    pub structure: String,
    /// Ray set.
    pub rays: RaySetKind,
    /// Query.
    pub query: Query,
    /// Threads.
    pub threads: usize,
    /// Rays in the set.
    pub ray_count: usize,
    /// Timed runs.
    pub reps: usize,
    /// Median seconds of the timed runs.
    pub seconds: f64,
    /// Median build time of the library on this scene and thread count, in milliseconds.
    pub build_ms: f64,
    /// Growth of the process's resident memory across the library's first build on this scene
    /// and thread count, in bytes (see [`crate::measure::BuildCost`]).
    pub build_resident_bytes: Option<u64>,
    /// Rays compared with brute force (0 when checks were off).
    pub checked: usize,
    /// Of those, how many disagreed.
    pub mismatches: usize,
    /// Speed over Embree's `rtcIntersect1` in the same cell, when Embree ran.
    pub ratio_to_embree: Option<f64>,
    /// Speed over obvhs in the same cell, when obvhs ran.
    pub ratio_to_obvhs: Option<f64>,
    /// The ray sets' seed.
    pub seed: u64,
}

impl Measurement {
    /// Millions of rays per second.
    pub fn mrays_per_s(&self) -> f64 {
        self.ray_count as f64 / self.seconds / 1e6
    }

    /// Bytes of resident memory per triangle the build added, if measured.
    pub fn build_bytes_per_triangle(&self) -> Option<f64> {
        self.build_resident_bytes.map(|b| b as f64 / self.triangles.max(1) as f64)
    }

    /// Millions of triangles built per second.
    pub fn build_mtris_per_s(&self) -> f64 {
        self.triangles as f64 / self.build_ms / 1e3
    }

    fn same_cell(&self, other: &Measurement) -> bool {
        self.scene == other.scene
            && self.rays == other.rays
            && self.query == other.query
            && self.threads == other.threads
    }
}

/// Fills in every measurement's ratios to Embree and obvhs in the same cell.
pub fn fill_ratios(all: &mut [Measurement]) {
    let speed_of = |all: &[Measurement], m: &Measurement, lib: LibraryKind| {
        all.iter().find(|o| o.library == lib && o.same_cell(m)).map(Measurement::mrays_per_s)
    };
    let ratios: Vec<_> = all
        .iter()
        .map(|m| {
            let speed = m.mrays_per_s();
            (
                speed_of(all, m, LibraryKind::Embree).map(|e| speed / e),
                speed_of(all, m, LibraryKind::Obvhs).map(|o| speed / o),
            )
        })
        .collect();
    for (m, (e, o)) in all.iter_mut().zip(ratios) {
        m.ratio_to_embree = e;
        m.ratio_to_obvhs = o;
    }
}

/// The CSV's columns, in order.
pub const CSV_COLUMNS: &[&str] = &[
    "scene",
    "library",
    "rays",
    "query",
    "threads",
    "mrays_per_s",
    "build_ms",
    "ratio_to_embree",
    "ratio_to_obvhs",
    "build_mtris_per_s",
    "build_bytes_per_triangle",
    "triangles",
    "ray_count",
    "reps",
    "checked",
    "mismatches",
    "seed",
    "structure",
];

/// A CSV field, quoted when it holds a comma, a quote or a line break.
fn field(s: &str) -> String {
    if s.contains([',', '"', '\n', '\r']) { format!("\"{}\"", s.replace('"', "\"\"")) } else { s.to_owned() }
}

fn optional(x: Option<f64>, decimals: usize) -> String {
    x.map_or_else(String::new, |x| format!("{x:.decimals$}"))
}

/// The CSV text: a header line and one line per measurement.
pub fn to_csv(all: &[Measurement]) -> String {
    let mut s = CSV_COLUMNS.join(",");
    s.push('\n');
    for m in all {
        let line = [
            field(&m.scene),
            m.library.name().to_owned(),
            m.rays.name().to_owned(),
            m.query.name().to_owned(),
            m.threads.to_string(),
            format!("{:.4}", m.mrays_per_s()),
            format!("{:.3}", m.build_ms),
            optional(m.ratio_to_embree, 4),
            optional(m.ratio_to_obvhs, 4),
            format!("{:.4}", m.build_mtris_per_s()),
            optional(m.build_bytes_per_triangle(), 1),
            m.triangles.to_string(),
            m.ray_count.to_string(),
            m.reps.to_string(),
            m.checked.to_string(),
            m.mismatches.to_string(),
            m.seed.to_string(),
            field(&m.structure),
        ];
        let _ = writeln!(s, "{}", line.join(","));
    }
    s
}

/// Writes `text` to `path` atomically: a temporary file beside it, flushed, then renamed over it.
pub fn write_atomically(path: &Path, text: &str) -> anyhow::Result<()> {
    let dir = match path.parent() {
        Some(d) if !d.as_os_str().is_empty() => d,
        _ => Path::new("."),
    };
    std::fs::create_dir_all(dir).with_context(|| format!("cannot create the folder {}", dir.display()))?;
    let name = path.file_name().with_context(|| format!("{} is not a file name", path.display()))?;
    let tmp = dir.join(format!(".{}.{}.tmp", name.to_string_lossy(), std::process::id()));
    let result = (|| {
        let mut f = std::fs::File::create(&tmp)?;
        f.write_all(text.as_bytes())?;
        f.sync_all()?;
        std::fs::rename(&tmp, path)
    })();
    if result.is_err() {
        let _ = std::fs::remove_file(&tmp);
    }
    result.with_context(|| format!("cannot write {}", path.display()))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sample(library: LibraryKind, seconds: f64) -> Measurement {
        Measurement {
            scene: "s".into(),
            triangles: 1000,
            library,
            structure: "a, b".into(),
            rays: RaySetKind::Primary,
            query: Query::Closest,
            threads: 2,
            ray_count: 1_000_000,
            reps: 5,
            seconds,
            build_ms: 2.0,
            build_resident_bytes: Some(64_000),
            checked: 10,
            mismatches: 0,
            ratio_to_embree: None,
            ratio_to_obvhs: None,
            seed: 1,
        }
    }

    #[test]
    fn ratios_compare_the_same_cell() {
        let mut all = vec![sample(LibraryKind::Embree, 0.1), sample(LibraryKind::Englobe, 0.2)];
        let mut other = sample(LibraryKind::Obvhs, 0.4);
        other.threads = 1;
        all.push(other);
        fill_ratios(&mut all);
        assert_eq!(all[1].ratio_to_embree, Some(0.5));
        assert_eq!(all[1].ratio_to_obvhs, None);
        assert_eq!(all[2].ratio_to_embree, None);
        assert_eq!(all[2].ratio_to_obvhs, Some(1.0));
        assert_eq!(all[1].mrays_per_s(), 5.0);
        assert_eq!(all[1].build_mtris_per_s(), 0.5);
    }

    #[test]
    fn csv_quotes_what_needs_it() {
        let csv = to_csv(&[sample(LibraryKind::Englobe, 0.2)]);
        let mut lines = csv.lines();
        assert_eq!(lines.next().unwrap(), CSV_COLUMNS.join(","));
        let row = lines.next().unwrap();
        assert!(row.starts_with("s,englobe,primary,closest,2,5.0000,2.000,,,0.5000,"), "{row}");
        assert!(row.ends_with(",\"a, b\""), "{row}");
        assert!(lines.next().is_none());
    }
}
