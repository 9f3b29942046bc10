//! The comparison as a picture (`englobe compare --plot FILE.svg`), written as SVG by hand (a few
//! rectangles and labels need no plotting library). Two panels share the structures' rows: rays per second
//! and exact tests per ray, each a horizontal bar per structure on a logarithmic axis, since brute
//! force sits orders of magnitude away from every structure on both. Each bar is labelled with its
//! value, so that the picture can be read without the table.

use std::fmt::Write as _;
use std::path::Path;

use crate::error::LabError;

/// What one bar pair shows.
#[derive(Clone, Debug, PartialEq)]
pub struct PlotRow {
    /// The structure's name.
    pub name: String,
    /// Rays per second of its render.
    pub rays_per_second: f64,
    /// Exact tests per ray of its render.
    pub exact_tests_per_ray: f64,
}

const WIDTH: f64 = 960.0;
const LABELS: f64 = 150.0;
const PANEL: f64 = 360.0;
const GAP: f64 = 50.0;
const TOP: f64 = 78.0;
const ROW: f64 = 24.0;
const BAR: f64 = 16.0;
const BOTTOM: f64 = 40.0;
const COLOURS: [&str; 2] = ["#3b75af", "#d17a22"];

/// A logarithmic axis over whole decades covering every positive value.
struct LogAxis {
    low: f64,
    high: f64,
}

impl LogAxis {
    fn covering(values: impl Iterator<Item = f64>) -> Self {
        let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
        for v in values.filter(|v| *v > 0.0 && v.is_finite()) {
            lo = lo.min(v);
            hi = hi.max(v);
        }
        if lo > hi {
            return LogAxis { low: 0.0, high: 1.0 };
        }
        let (low, mut high) = (lo.log10().floor(), hi.log10().ceil());
        if high <= low {
            high = low + 1.0;
        }
        LogAxis { low, high }
    }

    /// Position in `0..=1` of `v` (values at or below the axis' start sit at 0).
    fn at(&self, v: f64) -> f64 {
        if !(v > 0.0) {
            return 0.0;
        }
        ((v.log10() - self.low) / (self.high - self.low)).clamp(0.0, 1.0)
    }

    fn decades(&self) -> impl Iterator<Item = f64> + '_ {
        (self.low as i32..=self.high as i32).map(|e| 10f64.powi(e))
    }
}

fn escape(s: &str) -> String {
    s.replace('&', "&amp;").replace('<', "&lt;").replace('>', "&gt;").replace('"', "&quot;")
}

/// A number with three significant figures, in the unit that keeps it short.
fn short(v: f64) -> String {
    let (scaled, unit) = if v >= 1e6 {
        (v / 1e6, "M")
    } else if v >= 1e3 {
        (v / 1e3, "k")
    } else {
        (v, "")
    };
    let decimals = if scaled >= 100.0 {
        0
    } else if scaled >= 10.0 {
        1
    } else {
        2
    };
    format!("{scaled:.decimals$}{unit}")
}

fn tick_label(v: f64) -> String {
    if v >= 1e6 {
        format!("{}M", v / 1e6)
    } else if v >= 1e3 {
        format!("{}k", v / 1e3)
    } else {
        format!("{v}")
    }
}

/// A panel: its caption, its axis, and the value it shows of a row.
type Panel = (&'static str, LogAxis, fn(&PlotRow) -> f64);

/// The SVG document.
pub fn svg(title: &str, subtitle: &str, rows: &[PlotRow]) -> String {
    let height = TOP + ROW * rows.len() as f64 + BOTTOM;
    let mut out = String::new();
    let _ = writeln!(
        out,
        r#"<svg xmlns="http://www.w3.org/2000/svg" width="{WIDTH}" height="{height}" viewBox="0 0 {WIDTH} {height}" font-family="sans-serif" font-size="12">"#
    );
    let _ = writeln!(out, r#"<rect width="100%" height="100%" fill="white"/>"#);
    let _ = writeln!(out, r#"<text x="10" y="20" font-size="15" font-weight="bold">{}</text>"#, escape(title));
    let _ = writeln!(out, r##"<text x="10" y="38" fill="#555">{}</text>"##, escape(subtitle));
    let panels: [Panel; 2] = [
        (
            "rays per second (log scale, higher is better)",
            LogAxis::covering(rows.iter().map(|r| r.rays_per_second)),
            |r| r.rays_per_second,
        ),
        (
            "exact tests per ray (log scale, lower is better)",
            LogAxis::covering(rows.iter().map(|r| r.exact_tests_per_ray)),
            |r| r.exact_tests_per_ray,
        ),
    ];
    for (i, r) in rows.iter().enumerate() {
        let y = TOP + ROW * i as f64 + ROW / 2.0 + 4.0;
        let _ = writeln!(out, r#"<text x="{}" y="{y}" text-anchor="end">{}</text>"#, LABELS - 8.0, escape(&r.name));
    }
    for (p, (caption, axis, value)) in panels.iter().enumerate() {
        let x0 = LABELS + p as f64 * (PANEL + GAP);
        let bottom = TOP + ROW * rows.len() as f64;
        let _ = writeln!(out, r#"<text x="{x0}" y="{}" font-weight="bold">{caption}</text>"#, TOP - 22.0);
        for d in axis.decades() {
            let x = x0 + PANEL * axis.at(d);
            let _ = writeln!(
                out,
                r##"<line x1="{x:.1}" y1="{}" x2="{x:.1}" y2="{bottom}" stroke="#ddd"/><text x="{x:.1}" y="{}" text-anchor="middle" fill="#555">{}</text>"##,
                TOP - 6.0,
                bottom + 16.0,
                tick_label(d)
            );
        }
        for (i, r) in rows.iter().enumerate() {
            let v = value(r);
            let w = (PANEL * axis.at(v)).max(1.0);
            let y = TOP + ROW * i as f64 + (ROW - BAR) / 2.0;
            let _ = writeln!(out, r#"<rect x="{x0}" y="{y}" width="{w:.1}" height="{BAR}" fill="{}"/>"#, COLOURS[p]);
            // The value inside the bar's end if it is long enough, after it otherwise.
            let label = short(v);
            let inside = w > 8.0 * label.len() as f64 + 8.0;
            let (lx, anchor, colour) =
                if inside { (x0 + w - 4.0, "end", "white") } else { (x0 + w + 4.0, "start", "#222") };
            let _ = writeln!(
                out,
                r#"<text x="{lx:.1}" y="{:.1}" text-anchor="{anchor}" fill="{colour}">{label}</text>"#,
                y + BAR - 4.0
            );
        }
        let _ = writeln!(out, r##"<line x1="{x0}" y1="{}" x2="{x0}" y2="{bottom}" stroke="#222"/>"##, TOP - 6.0);
    }
    out.push_str("</svg>\n");
    out
}

/// Writes the SVG to `path`, atomically.
pub fn write_svg(path: &Path, title: &str, subtitle: &str, rows: &[PlotRow]) -> Result<(), LabError> {
    let text = svg(title, subtitle, rows);
    englobe_render::output::write_atomically(path, |w| {
        use std::io::Write;
        w.write_all(text.as_bytes()).map_err(|error| englobe_render::OutputError::Io { path: path.to_owned(), error })
    })
    .map_err(|source| LabError::Plot { path: path.to_owned(), source })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn rows() -> Vec<PlotRow> {
        vec![
            PlotRow { name: "none".into(), rays_per_second: 2_000.0, exact_tests_per_ray: 69_451.0 },
            PlotRow { name: "kdtree".into(), rays_per_second: 2.5e6, exact_tests_per_ray: 1.9 },
            PlotRow { name: "a<b".into(), rays_per_second: 0.0, exact_tests_per_ray: 7.15 },
        ]
    }

    #[test]
    fn one_bar_per_structure_and_panel_with_its_value() {
        let s = svg("bunny & co", "320x240", &rows());
        assert!(s.starts_with("<svg") && s.trim_end().ends_with("</svg>"));
        assert_eq!(s.matches("<rect x=").count(), 6);
        for label in ["69.5k", "2.50M", "1.90", "7.15", "a&lt;b", "bunny &amp; co"] {
            assert!(s.contains(label), "{label} in\n{s}");
        }
        // Decades from 1 to 100 000 on the tests axis, 1 000 to 10 000 000 on the speed axis.
        assert!(s.contains(">100k<") && s.contains(">10M<") && s.contains(">1k<"));
    }

    #[test]
    fn the_log_axis_covers_whole_decades() {
        let a = LogAxis::covering([3.0, 420.0].into_iter());
        assert_eq!((a.low, a.high), (0.0, 3.0));
        assert_eq!(a.at(1.0), 0.0);
        assert!((a.at(10.0) - 1.0 / 3.0).abs() < 1e-12);
        assert_eq!(a.at(0.0), 0.0);
        let empty = LogAxis::covering(std::iter::empty());
        assert_eq!(empty.decades().count(), 2);
        let single = LogAxis::covering([10.0].into_iter());
        assert_eq!((single.low, single.high), (1.0, 2.0));
    }

    #[test]
    fn short_numbers() {
        assert_eq!(short(1.234), "1.23");
        assert_eq!(short(12.34), "12.3");
        assert_eq!(short(1234.0), "1.23k");
        assert_eq!(short(195_878.0), "196k");
        assert_eq!(short(2.5e6), "2.50M");
    }
}
