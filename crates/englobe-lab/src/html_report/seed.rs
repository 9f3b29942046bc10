//! The seed report's experiment as a page to look at (`englobe experiment seed --report DIR`):
//! the report's claims checked against ours, then each of its four tests with its table (our
//! counts at the size run beside the report's own at its 512 x 512, Deneux and Joniaux 2009,
//! section 6), the plot of rays per second and exact tests per ray, the image and one cost
//! heatmap per structure on a scale shared within the test. One self-contained file, as the
//! comparison's page (see [`super::page`]).

use std::fmt::Write;
use std::path::{Path, PathBuf};

use englobe::AccelKind;
use englobe_scene::parse_scene;

use super::page::{ReportPictures, TAIL, escape, head, inline_svg, pictures, render_pictures_of, write_page};
use crate::error::LabError;
use crate::plot::{PlotRow, svg};
use crate::report::grouped;
use crate::seed_experiment::{SeedExperiment, format_report_count};
use crate::seed_report::{ReportFigures, SEED_TESTS};

/// Width of the seed page's pictures: two tests' pictures of five structures fit a projector.
pub const SEED_PREVIEW_WIDTH: u32 = 256;

/// The pictures of every test the experiment ran, in its order: the test's number and its
/// image and heatmaps (every structure it ran but the lower bound, which is a yardstick, not a
/// structure one traces with).
pub fn render_seed_pictures(experiment: &SeedExperiment) -> Result<Vec<(u32, ReportPictures)>, LabError> {
    let mut out = Vec::new();
    for test in SEED_TESTS.iter().filter(|t| experiment.rows.iter().any(|r| r.test == t.number)) {
        let scene = parse_scene(test.text, test.file.as_ref())?;
        let kinds: Vec<AccelKind> = experiment
            .rows
            .iter()
            .filter(|r| r.test == test.number && r.accel != AccelKind::Bound.name())
            .filter_map(|r| r.accel.parse().ok())
            .collect();
        let size = (experiment.width, experiment.height);
        out.push((test.number, render_pictures_of(&scene, &kinds, size, experiment.samples, SEED_PREVIEW_WIDTH)?));
    }
    Ok(out)
}

/// The page of `experiment` with the pictures of its tests.
pub fn seed_page(experiment: &SeedExperiment, pictures_of: &[(u32, ReportPictures)]) -> String {
    let e = experiment;
    let mut p = head("englobe experiment seed: the seed report's four tests");
    let _ = writeln!(
        p,
        "<p>The seed report (Deneux and Joniaux 2009, section 6) counts calls to the exact intersection function \
         over all the rays of one image, before and after its BVH. Our scenes for its tests, rendered at {}x{}, \
         {} sample(s) per pixel, {} threads{}. Absolute counts are ours at {0}x{1} and the report's at its 512x512: \
         they compare only at 512x512; the reductions (fewer) compare at any size. Seconds are the best of a few \
         renders with counting on.</p>",
        e.width,
        e.height,
        e.samples,
        e.threads,
        if cfg!(debug_assertions) { ", debug build (times are not representative)" } else { "" }
    );
    let _ = writeln!(p, "<h2>The report's claims and ours</h2>\n<ul id=\"claims\">");
    for c in &e.checks {
        let (class, mark) = if c.holds { ("yes", "yes") } else { ("no", "NO") };
        let why = c.why_not.as_ref().map_or(String::new(), |w| format!("<br>why not: {}", escape(w)));
        let _ = writeln!(p, "<li class=\"{class}\">[{mark}] {}{why}</li>", escape(&c.claim));
    }
    let _ = writeln!(p, "</ul>");
    for test in SEED_TESTS.iter().filter(|t| e.rows.iter().any(|r| r.test == t.number)) {
        let rows: Vec<_> = e.rows.iter().filter(|r| r.test == test.number).collect();
        let primitives = rows.first().map_or(0, |r| r.primitives);
        let _ = writeln!(
            p,
            "<h2 id=\"test-{0}\">Test {0}: {1}</h2>\n<p>{2}, {primitives} spheres.</p>\n<table id=\"table-{0}\">",
            test.number,
            escape(test.title),
            escape(test.file)
        );
        let _ = writeln!(
            p,
            "<tr><th>structure</th><th>rays</th><th>exact tests {0}x{1}</th><th>fewer</th><th>seconds</th>\
             <th>image</th><th>report 512x512</th><th>report fewer</th></tr>",
            e.width, e.height
        );
        for r in &rows {
            let reference = r.accel == AccelKind::None.name();
            let fewer = if reference { "-".to_owned() } else { format!("{:.1} %", r.reduction_percent) };
            let image = match (reference, r.image_identical) {
                (true, _) => "reference".to_owned(),
                (false, true) => "identical".to_owned(),
                (false, false) => format!("<span class=\"differ\">{} differ</span>", r.differing_pixels),
            };
            let words = match (test.report, reference, r.accel) {
                (ReportFigures::Words { before, .. }, true, _) => before,
                (ReportFigures::Words { after, .. }, false, "bvh-seed") => after,
                _ => "",
            };
            let report = r.report_exact_tests.map_or(escape(words), format_report_count);
            let report_fewer = r.report_reduction_percent.map_or(String::new(), |f| format!("{f:.1} %"));
            let _ = writeln!(
                p,
                "<tr><td>{}</td><td>{}</td><td>{}</td><td>{fewer}</td><td>{:.3}</td><td>{image}</td><td>{report}</td>\
                 <td>{report_fewer}</td></tr>",
                escape(r.accel),
                grouped(r.rays),
                grouped(r.exact_tests),
                r.seconds
            );
        }
        let _ = writeln!(p, "</table>");
        let plot_rows: Vec<PlotRow> = rows
            .iter()
            .map(|r| PlotRow {
                name: r.accel.to_owned(),
                rays_per_second: if r.seconds > 0.0 { r.rays as f64 / r.seconds } else { 0.0 },
                exact_tests_per_ray: if r.rays > 0 { r.exact_tests as f64 / r.rays as f64 } else { 0.0 },
            })
            .collect();
        let subtitle = format!("{}x{}, {} sample(s) per pixel, counting on", e.width, e.height, e.samples);
        p += inline_svg(&svg(&format!("test {}: {}", test.number, test.title), &subtitle, &plot_rows));
        if let Some((_, pics)) = pictures_of.iter().find(|(n, _)| *n == test.number) {
            let _ = writeln!(
                p,
                "<p>Cost is nodes visited plus exact tests per pixel, at {}x{} and one sample per pixel, on one {} \
                 scale shared by the structures of this test.</p>",
                pics.width,
                pics.height,
                escape(&pics.scale.describe())
            );
            pictures(&mut p, pics);
        }
    }
    p + TAIL
}

/// Writes the page into `dir` (created if needed) as `index.html`, atomically; returns its path.
pub fn write_seed_report(
    dir: &Path,
    experiment: &SeedExperiment,
    pictures_of: &[(u32, ReportPictures)],
) -> Result<PathBuf, LabError> {
    write_page(dir, &seed_page(experiment, pictures_of))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::seed_experiment::{SeedOptions, run_seed};

    #[test]
    fn the_page_holds_the_claims_and_each_test_s_table_plot_and_pictures() {
        let options = SeedOptions {
            size: Some(24),
            tests: vec![1, 4],
            accel: vec![AccelKind::BvhSeed, AccelKind::BvhWide],
            ..SeedOptions::default()
        };
        let experiment = run_seed(&options, &mut |_| {}).unwrap();
        let pictures_of = render_seed_pictures(&experiment).unwrap();
        assert_eq!(pictures_of.iter().map(|(n, _)| *n).collect::<Vec<_>>(), [1, 4]);
        for (_, pics) in &pictures_of {
            let names: Vec<&str> = pics.heatmaps.iter().map(|(n, _)| n.as_str()).collect();
            assert_eq!(names, ["none", "bvh-seed", "bvh-wide"], "every structure but the bound");
            assert_eq!((pics.width, pics.height), (24, 24));
        }
        let page = seed_page(&experiment, &pictures_of);
        // Two tests, each the image and three heatmaps.
        super::super::page::assert_self_contained(&page, 8);
        assert!(page.contains("<title>englobe experiment seed: the seed report's four tests</title>"));
        // Every claim, marked as the text output marks it, with its reason when it fails.
        let claims = &page[page.find("<ul id=\"claims\">").unwrap()..];
        let claims = &claims[..claims.find("</ul>").unwrap()];
        assert_eq!(claims.matches("<li ").count(), experiment.checks.len());
        for c in &experiment.checks {
            let mark = if c.holds { "<li class=\"yes\">[yes] " } else { "<li class=\"no\">[NO] " };
            assert!(claims.contains(&format!("{mark}{}", escape(&c.claim))), "{}", c.claim);
            if let Some(why) = &c.why_not {
                assert!(claims.contains(&format!("why not: {}", escape(why))));
            }
        }
        // One table per test: a header and a row per structure, the bound included.
        for test in [1, 4] {
            let start = page.find(&format!("<table id=\"table-{test}\">")).unwrap();
            let table = &page[start..start + page[start..].find("</table>").unwrap()];
            assert_eq!(table.matches("<tr>").count(), 5, "test {test}: none, bvh-seed, bvh-wide, bound");
            for name in ["none", "bvh-seed", "bvh-wide", "bound"] {
                assert!(table.contains(&format!("<tr><td>{name}</td>")), "test {test}: {name}");
            }
            assert!(table.contains("exact tests 24x24") && table.contains("report 512x512"));
        }
        assert!(!page.contains("<table id=\"table-2\">"), "tests not run are left out");
        // Beside our counts, the report's: test 1's in its notation, test 4's in its words.
        let one = &page[page.find("<table id=\"table-1\">").unwrap()..page.find("<h2 id=\"test-4\">").unwrap()];
        assert!(one.contains("<td>2.51978e7</td>") && one.contains("<td>1.61632e7</td><td>35.8 %</td>"), "{one}");
        let four = &page[page.find("<table id=\"table-4\">").unwrap()..];
        assert!(four.contains("&lt; 2 % done after minutes") && four.contains("done in seconds"));
        assert_eq!(page.matches("<svg").count(), 2, "a plot per test");
        assert_eq!(page.matches("shared by the structures of this test").count(), 2);
    }
}
