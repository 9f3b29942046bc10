//! The comparison as a page to look at (`englobe compare SCENE --report DIR`): one HTML file that
//! holds everything (the tables, the SVG plot, the rendered image and one cost heatmap per
//! structure as PNG data, no script, no link outside it), so that it opens from a folder, a mail or
//! a projector with no server and no network.
//!
//! The heatmaps share one scale, the largest cost of any structure, so that their colours compare
//! across structures: the same colour is the same work. They are rendered at a preview size (a
//! few hundred pixels wide) whatever the size compared, since a heatmap is looked at, not
//! measured.

use std::fmt::Write;
use std::io::Write as _;
use std::path::Path;

use englobe::AccelKind;
use englobe_render::{Heatmap, HeatmapScale, OutputError};
use englobe_scene::Scene;

use crate::compare::Comparison;
use crate::error::LabError;
use crate::measure::{RenderSettings, build, render};
use crate::plot::svg;

/// Width of the pictures on the page, in pixels (the height follows the scene's aspect ratio).
pub const PREVIEW_WIDTH: u32 = 320;

/// The pictures of the page: the image and one heatmap per structure, as PNG files.
#[derive(Clone, Debug)]
pub struct ReportPictures {
    /// The rendered image.
    pub image_png: Vec<u8>,
    /// One heatmap per structure, in the comparison's order: its name and the PNG.
    pub heatmaps: Vec<(String, Vec<u8>)>,
    /// The scale they share.
    pub scale: HeatmapScale,
    /// Their size, in pixels (the heatmaps add their colour bar below).
    pub width: u32,
    /// Their height.
    pub height: u32,
}

/// Renders the pictures for `comparison` of `scene`: the image with the first structure, then the
/// cost of every structure compared, at a preview size, on one shared scale.
pub fn render_pictures(scene: &Scene, comparison: &Comparison) -> Result<ReportPictures, LabError> {
    let width = PREVIEW_WIDTH.min(comparison.width);
    let height = ((comparison.height as f64 * width as f64 / comparison.width as f64).round() as u32).max(1);
    let settings = RenderSettings { width, height, samples: 1, count_work: false, stride: 1 };
    let mut image_png = Vec::new();
    let mut costs = Vec::new();
    for row in &comparison.rows {
        let kind: AccelKind = row.accel.parse().map_err(|_| LabError::Render(unknown(row.accel)))?;
        let (world, _) = build(scene, kind)?;
        let out = englobe_render::Renderer::new(scene, &world)
            .size(settings.width, settings.height)
            .samples(settings.samples)
            .record_cost(true)
            .render()?;
        if image_png.is_empty() {
            let film = render(scene, &world, RenderSettings { samples: comparison.samples, ..settings })?.film;
            image_png = png(film.to_srgb8(), width, height)?;
        }
        costs.push((row.accel.to_owned(), out.cost.expect("the cost was recorded")));
    }
    let max = costs.iter().map(|(_, c)| c.max()).max().unwrap_or(0);
    let scale = HeatmapScale::log(max);
    let heatmaps = costs
        .iter()
        .map(|(name, cost)| {
            let img = Heatmap::new(width, height, cost.values(), scale).to_rgb8();
            let (w, h) = (img.width(), img.height());
            Ok((name.clone(), png(img.into_raw(), w, h)?))
        })
        .collect::<Result<_, LabError>>()?;
    Ok(ReportPictures { image_png, heatmaps, scale, width, height })
}

fn unknown(name: &str) -> englobe_render::RenderError {
    englobe_render::RenderError::Limits(format!("unknown structure `{name}`"))
}

fn png(rgb: Vec<u8>, width: u32, height: u32) -> Result<Vec<u8>, LabError> {
    let img = image::RgbImage::from_raw(width, height, rgb).expect("a film holds width x height pixels");
    let mut bytes = std::io::Cursor::new(Vec::new());
    img.write_to(&mut bytes, image::ImageFormat::Png)
        .map_err(|error| OutputError::Encode { path: "report.png".into(), error })?;
    Ok(bytes.into_inner())
}

/// The page of `comparison` with `pictures`.
pub fn report_page(comparison: &Comparison, pictures: &ReportPictures) -> String {
    let c = comparison;
    let mut p = String::new();
    let title = format!("englobe compare: {}", escape(&c.scene));
    let _ = write!(
        p,
        "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n<title>{title}</title>\n<style>\n\
         body {{ font: 15px/1.4 system-ui, sans-serif; margin: 2em; color: #222; }}\n\
         table {{ border-collapse: collapse; margin: 1em 0; }}\n\
         th, td {{ padding: 0.2em 0.7em; border-bottom: 1px solid #ddd; text-align: right; }}\n\
         th:first-child, td:first-child {{ text-align: left; }}\n\
         .pictures {{ display: flex; flex-wrap: wrap; gap: 1em; }}\n\
         figure {{ margin: 0; }} figcaption {{ text-align: center; font-size: 90%; }}\n\
         .differ {{ color: #b00; font-weight: bold; }}\n</style>\n</head>\n<body>\n<h1>{title}</h1>\n"
    );
    let _ = writeln!(
        p,
        "<p>{} primitives, {}x{}, {} sample(s) per pixel, {} threads; every structure renders the same image, \
         only the work differs.</p>",
        c.primitives, c.width, c.height, c.samples, c.threads
    );
    let _ = writeln!(p, "<h2>Speed and work</h2>\n<table id=\"speed\">");
    let _ = writeln!(
        p,
        "<tr><th>structure</th><th>build (s)</th><th>memory (KiB)</th><th>Mrays/s</th><th>speed-up</th>\
         <th>exact tests/ray</th><th>nodes/ray</th><th>image</th></tr>"
    );
    for r in &c.rows {
        let image = if r.image_equal {
            "same".to_owned()
        } else {
            format!("<span class=\"differ\">{} differ</span>", r.differing_pixels)
        };
        let _ = writeln!(
            p,
            "<tr><td>{}</td><td>{:.3}</td><td>{:.0}</td><td>{:.2}</td><td>{:.1}x</td><td>{:.2}</td><td>{:.2}</td><td>{image}</td></tr>",
            escape(r.accel),
            r.build_seconds,
            r.memory_bytes as f64 / 1024.0,
            r.rays_per_second / 1e6,
            r.speedup_vs_none,
            r.exact_tests_per_ray,
            r.nodes_visited_per_ray
        );
    }
    let _ = writeln!(p, "</table>\n<h2>Quality</h2>\n<table id=\"quality\">");
    let _ = writeln!(
        p,
        "<tr><th>structure</th><th>SAH cost</th><th>vs sweep</th><th>depth</th><th>leaves</th><th>refs/primitive</th></tr>"
    );
    for r in c.rows.iter().filter(|r| r.accel != AccelKind::None.name()) {
        let sah = r.sah_cost.map_or("-".to_owned(), |s| format!("{s:.2}"));
        let vs = r.sah_vs_sweep.map_or("-".to_owned(), |s| format!("{s:.3}"));
        let _ = writeln!(
            p,
            "<tr><td>{}</td><td>{sah}</td><td>{vs}</td><td>{}</td><td>{}</td><td>{:.2}</td></tr>",
            escape(r.accel),
            r.depth,
            r.leaves,
            r.refs_per_prim
        );
    }
    let _ = writeln!(p, "</table>\n<h2>Rays per second and exact tests per ray</h2>");
    let (rows, subtitle) = c.plot();
    let plot = svg(&c.scene, &subtitle, &rows);
    // Inline SVG: the XML declaration, if any, belongs to a file, not to a page.
    p += plot.trim_start_matches(|ch| ch != '<').split_once("?>").map_or(plot.as_str(), |(_, rest)| rest);
    let _ = writeln!(
        p,
        "\n<h2>The image and the work per pixel</h2>\n<p>Cost is nodes visited plus exact tests per pixel, at {}x{} \
         and one sample per pixel, on one {} scale shared by every structure (the same colour is the same work).</p>",
        pictures.width,
        pictures.height,
        escape(&pictures.scale.describe())
    );
    let _ = writeln!(p, "<div class=\"pictures\">");
    picture(&mut p, "image", &pictures.image_png, "the image");
    for (name, bytes) in &pictures.heatmaps {
        picture(&mut p, "heatmap", bytes, name);
    }
    let _ = writeln!(p, "</div>\n</body>\n</html>");
    p
}

fn picture(p: &mut String, class: &str, png: &[u8], caption: &str) {
    let _ = writeln!(
        p,
        "<figure class=\"{class}\"><img alt=\"{0}\" src=\"data:image/png;base64,{1}\"><figcaption>{0}</figcaption></figure>",
        escape(caption),
        base64(png)
    );
}

/// Writes the page into `dir` (created if needed) as `index.html`, atomically; returns its path.
pub fn write_report(
    dir: &Path,
    comparison: &Comparison,
    pictures: &ReportPictures,
) -> Result<std::path::PathBuf, LabError> {
    std::fs::create_dir_all(dir).map_err(|source| LabError::CreateDir { path: dir.to_owned(), source })?;
    let path = dir.join("index.html");
    let page = report_page(comparison, pictures);
    englobe_render::output::write_atomically(&path, |w| {
        w.write_all(page.as_bytes()).map_err(|error| OutputError::Io { path: path.clone(), error })
    })?;
    Ok(path)
}

fn escape(s: &str) -> String {
    s.replace('&', "&amp;").replace('<', "&lt;").replace('>', "&gt;").replace('"', "&quot;")
}

/// Standard base64 with padding (RFC 4648), for the data URIs.
fn base64(bytes: &[u8]) -> String {
    const ALPHABET: &[u8; 64] = b"ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    let mut out = String::with_capacity(bytes.len().div_ceil(3) * 4);
    for chunk in bytes.chunks(3) {
        let b = [chunk[0], *chunk.get(1).unwrap_or(&0), *chunk.get(2).unwrap_or(&0)];
        let n = (b[0] as u32) << 16 | (b[1] as u32) << 8 | b[2] as u32;
        for k in 0..4 {
            if k <= chunk.len() {
                out.push(ALPHABET[(n >> (18 - 6 * k) & 63) as usize] as char);
            } else {
                out.push('=');
            }
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::compare::{CompareOptions, run_compare};

    #[test]
    fn base64_is_rfc_4648() {
        for (plain, coded) in [("", ""), ("f", "Zg=="), ("fo", "Zm8="), ("foo", "Zm9v"), ("foobar", "Zm9vYmFy")] {
            assert_eq!(base64(plain.as_bytes()), coded);
        }
    }

    #[test]
    fn the_page_holds_its_tables_plot_and_pictures_and_nothing_outside() {
        let scene = englobe_scene::parse_scene(englobe_render::DEFAULT_SCENE, "default.toml".as_ref()).unwrap();
        let options = CompareOptions {
            width: Some(48),
            height: Some(36),
            spp: Some(1),
            accel: vec![AccelKind::BvhSah, AccelKind::Grid],
            full: true,
            ..CompareOptions::default()
        };
        let comparison = run_compare(&scene, "default <scene>", &options, &mut |_| {}).unwrap();
        let pictures = render_pictures(&scene, &comparison).unwrap();
        assert_eq!(pictures.heatmaps.len(), 3, "none, bvh-sah and grid");
        let page = report_page(&comparison, &pictures);
        assert!(page.starts_with("<!DOCTYPE html>") && page.trim_end().ends_with("</html>"));
        assert!(page.contains("<title>englobe compare: default &lt;scene&gt;</title>"), "names are escaped");
        let speed = &page[page.find("<table id=\"speed\">").unwrap()..];
        let speed = &speed[..speed.find("</table>").unwrap()];
        assert_eq!(speed.matches("<tr>").count(), 4, "a header and one row per structure");
        for name in ["none", "bvh-sah", "grid"] {
            assert!(speed.contains(&format!("<tr><td>{name}</td>")), "{name}");
            assert!(page.contains(&format!("<figcaption>{name}</figcaption>")), "a heatmap of {name}");
        }
        assert_eq!(page.matches("<img ").count(), 4, "the image and three heatmaps");
        assert_eq!(page.matches("src=\"data:image/png;base64,").count(), 4, "every picture is inside the page");
        assert_eq!(page.matches("http").count(), page.matches("http://www.w3.org/").count(), "no link but namespaces");
        assert!(!page.contains("<script"), "no script");
        assert_eq!(page.matches("<svg").count(), 1);
        assert!(!page.contains("<?xml"));
        assert!(page.contains("scale shared by every structure"));
        // The heatmaps share one scale, which tops at the largest cost of any structure: brute
        // force's, which tests every object for every ray.
        assert!(pictures.scale.cost_at(1.0) > 0);
        assert!(page.contains(&escape(&pictures.scale.describe())));
    }
}
