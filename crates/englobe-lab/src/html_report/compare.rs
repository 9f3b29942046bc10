//! The comparison as a page to look at (`englobe compare SCENE --report DIR`): one HTML file that
//! holds everything (the tables, the SVG plot, the rendered image and one cost heatmap per
//! structure as PNG data, no script, no link outside it), so that it opens from a folder, a mail or
//! a projector with no server and no network (see [`super::page`], which it shares with the seed
//! experiment's page).

use std::fmt::Write;
use std::path::Path;

use englobe::AccelKind;
use englobe_scene::Scene;

use super::page::PREVIEW_WIDTH;
use super::page::{ReportPictures, TAIL, escape, head, inline_svg, render_pictures_of, write_page};
use crate::compare::Comparison;
use crate::error::LabError;
use crate::plot::svg;

/// Renders the pictures for `comparison` of `scene`: the image with the first structure, then the
/// cost of every structure compared, at a preview size, on one shared scale.
pub fn render_pictures(scene: &Scene, comparison: &Comparison) -> Result<ReportPictures, LabError> {
    let kinds = comparison
        .rows
        .iter()
        .map(|row| row.accel.parse::<AccelKind>().map_err(|_| LabError::Render(unknown(row.accel))))
        .collect::<Result<Vec<_>, _>>()?;
    render_pictures_of(scene, &kinds, (comparison.width, comparison.height), comparison.samples, PREVIEW_WIDTH)
}

fn unknown(name: &str) -> englobe_render::RenderError {
    englobe_render::RenderError::Limits(format!("unknown structure `{name}`"))
}

/// The page of `comparison` with `pictures`.
pub fn report_page(comparison: &Comparison, pictures: &ReportPictures) -> String {
    let c = comparison;
    let mut p = head(&format!("englobe compare: {}", c.scene));
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
    p += inline_svg(&plot);
    let _ = writeln!(
        p,
        "\n<h2>The image and the work per pixel</h2>\n<p>Cost is nodes visited plus exact tests per pixel, at {}x{} \
         and one sample per pixel, on one {} scale shared by every structure (the same colour is the same work).</p>",
        pictures.width,
        pictures.height,
        escape(&pictures.scale.describe())
    );
    super::page::pictures(&mut p, pictures);
    p + TAIL
}

/// Writes the page into `dir` (created if needed) as `index.html`, atomically; returns its path.
pub fn write_report(
    dir: &Path,
    comparison: &Comparison,
    pictures: &ReportPictures,
) -> Result<std::path::PathBuf, LabError> {
    write_page(dir, &report_page(comparison, pictures))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::compare::{CompareOptions, run_compare};

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
        super::super::page::assert_self_contained(&page, 4);
        assert!(page.contains("<title>englobe compare: default &lt;scene&gt;</title>"), "names are escaped");
        let speed = &page[page.find("<table id=\"speed\">").unwrap()..];
        let speed = &speed[..speed.find("</table>").unwrap()];
        assert_eq!(speed.matches("<tr>").count(), 4, "a header and one row per structure");
        for name in ["none", "bvh-sah", "grid"] {
            assert!(speed.contains(&format!("<tr><td>{name}</td>")), "{name}");
            assert!(page.contains(&format!("<figcaption>{name}</figcaption>")), "a heatmap of {name}");
        }
        assert_eq!(page.matches("<svg").count(), 1);
        assert!(page.contains("scale shared by every structure"));
        // The heatmaps share one scale, which tops at the largest cost of any structure: brute
        // force's, which tests every object for every ray.
        assert!(pictures.scale.cost_at(1.0) > 0);
        assert!(page.contains(&escape(&pictures.scale.describe())));
    }
}
