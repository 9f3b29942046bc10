//! The tables printed after each scene and thread count: one row per library, one column per
//! cell (ray set and query) with the speed in million rays per second and the ratio to Embree's
//! `rtcIntersect1` in the same cell, or to obvhs when Embree is not built in; then the build time
//! and the agreement with brute force.

use std::fmt::Write as _;

use crate::measure::Query;
use crate::rays::RaySetKind;
use crate::registry::LibraryKind;
use crate::results::Measurement;

/// A column of the table: a ray set and a query.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct Cell {
    /// Ray set.
    pub rays: RaySetKind,
    /// Query.
    pub query: Query,
}

impl Cell {
    /// The four cells: primary closest, random closest, random any, bounce closest.
    pub const DEFAULT: [Cell; 4] = [
        Cell { rays: RaySetKind::Primary, query: Query::Closest },
        Cell { rays: RaySetKind::Random, query: Query::Closest },
        Cell { rays: RaySetKind::Random, query: Query::Any },
        Cell { rays: RaySetKind::Bounce, query: Query::Closest },
    ];

    /// Every combination.
    pub fn all() -> Vec<Cell> {
        RaySetKind::ALL
            .into_iter()
            .flat_map(|rays| [Query::Closest, Query::Any].map(|query| Cell { rays, query }))
            .collect()
    }

    /// `primary-closest` and so on.
    pub fn name(&self) -> String {
        format!("{}-{}", self.rays.name(), self.query.name())
    }

    /// Parses a name given by [`Cell::name`].
    pub fn parse(s: &str) -> Result<Cell, String> {
        Cell::all().into_iter().find(|c| c.name() == s).ok_or_else(|| {
            let names: Vec<_> = Cell::all().iter().map(Cell::name).collect();
            format!("unknown cell `{s}`; expected one of: {}", names.join(", "))
        })
    }
}

/// The table for the measurements of one scene and thread count.
pub fn table(group: &[Measurement], cells: &[Cell]) -> String {
    let Some(first) = group.first() else { return String::new() };
    let has_embree = group.iter().any(|m| m.library == LibraryKind::Embree);
    let reference = if has_embree { "ratio to embree rtcIntersect1" } else { "ratio to obvhs; Embree not built in" };
    let mut s = String::new();
    let _ = writeln!(
        s,
        "\n{}: {} triangles, {} thread{}; Mrays/s ({reference}), median of {}",
        first.scene,
        first.triangles,
        first.threads,
        if first.threads == 1 { "" } else { "s" },
        first.reps
    );
    let _ = write!(s, "{:<18}{:>10}{:>8}", "library", "build ms", "B/tri");
    for c in cells {
        let _ = write!(s, "{:>18}", c.name());
    }
    let _ = writeln!(s, "  agreement");
    let mut libraries: Vec<LibraryKind> = group.iter().map(|m| m.library).collect();
    libraries.dedup();
    for lib in libraries {
        let rows: Vec<&Measurement> = group.iter().filter(|m| m.library == lib).collect();
        let bytes = rows[0].build_bytes_per_triangle().map_or("-".to_owned(), |b| format!("{b:.0}"));
        let _ = write!(s, "{:<18}{:>10.1}{bytes:>8}", lib.name(), rows[0].build_ms);
        for c in cells {
            let cell = match rows.iter().find(|m| m.rays == c.rays && m.query == c.query) {
                Some(m) => {
                    let ratio = if has_embree { m.ratio_to_embree } else { m.ratio_to_obvhs };
                    format!("{:.2} ({})", m.mrays_per_s(), ratio.map_or("-".to_owned(), |r| format!("{r:.2}")))
                }
                None => "-".to_owned(),
            };
            let _ = write!(s, "{cell:>18}");
        }
        let checked: usize = rows.iter().map(|m| m.checked).sum();
        let mismatches: usize = rows.iter().map(|m| m.mismatches).sum();
        let agreement = if checked == 0 { "not checked".to_owned() } else { format!("{mismatches}/{checked} differ") };
        let _ = writeln!(s, "  {agreement}");
    }
    for lib in group.iter().map(|m| m.library).collect::<std::collections::BTreeSet<_>>() {
        if let Some(m) = group.iter().find(|m| m.library == lib) {
            let _ = writeln!(s, "  {:<16} {}", lib.name(), m.structure);
        }
    }
    s
}

/// The processor, from `/proc/cpuinfo` where there is one, and its widest vector extension.
pub fn machine_description() -> String {
    let cores = std::thread::available_parallelism().map_or(0, |n| n.get());
    let info = std::fs::read_to_string("/proc/cpuinfo").unwrap_or_default();
    let field = |name: &str| {
        info.lines().find(|l| l.starts_with(name)).and_then(|l| l.split_once(':')).map(|(_, v)| v.trim().to_owned())
    };
    let model = field("model name").unwrap_or_else(|| std::env::consts::ARCH.to_owned());
    let flags = field("flags").unwrap_or_default();
    let has = |f: &str| flags.split_whitespace().any(|x| x == f);
    let simd = if has("avx512f") {
        "AVX-512"
    } else if has("avx2") {
        "AVX2"
    } else if has("sse4_2") {
        "SSE4.2"
    } else {
        "baseline SIMD"
    };
    format!("{model}, {cores} hardware threads, {simd}")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn cells_round_trip() {
        for c in Cell::all() {
            assert_eq!(Cell::parse(&c.name()).unwrap(), c);
        }
        assert_eq!(Cell::all().len(), 6);
        assert!(Cell::parse("shadow-any").is_err());
    }
}
