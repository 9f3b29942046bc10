//! What every report page shares: one self-contained HTML file (the style in its head, pictures
//! as PNG data URIs, SVG inline, no script, no link outside it), so that it opens from a folder, a
//! mail or a projector with no server and no network; the pictures of the scene and of its work
//! per structure (cost heatmaps on one shared scale); and the page's atomic writing.
//!
//! The heatmaps share one scale, the largest cost of any structure shown, so that their colours
//! compare across structures: the same colour is the same work. They are rendered at a preview
//! size (a few hundred pixels wide) whatever the size measured, since a heatmap is looked at, not
//! measured.

use std::fmt::Write;
use std::io::Write as _;
use std::path::{Path, PathBuf};

use englobe::AccelKind;
use englobe_render::{Heatmap, HeatmapScale, OutputError, Renderer};
use englobe_scene::Scene;

use crate::error::LabError;
use crate::measure::{RenderSettings, build, render};

/// Width of the pictures on a page, in pixels (the height follows the scene's aspect ratio).
pub const PREVIEW_WIDTH: u32 = 320;

/// The pictures of one scene: its image and one heatmap per structure, as PNG files.
#[derive(Clone, Debug)]
pub struct ReportPictures {
    /// The rendered image.
    pub image_png: Vec<u8>,
    /// One heatmap per structure, in the order asked: its name and the PNG.
    pub heatmaps: Vec<(String, Vec<u8>)>,
    /// The scale they share.
    pub scale: HeatmapScale,
    /// Their size, in pixels (the heatmaps add their colour bar below).
    pub width: u32,
    /// Their height.
    pub height: u32,
}

/// Renders the pictures of `scene` as measured at `width` x `height`, at a preview size of at
/// most `max_width`: the image with the first structure of `kinds` (`samples` per pixel), then
/// the cost of every structure of `kinds`, one sample per pixel, on one shared scale.
pub fn render_pictures_of(
    scene: &Scene,
    kinds: &[AccelKind],
    (width, height): (u32, u32),
    samples: u32,
    max_width: u32,
) -> Result<ReportPictures, LabError> {
    let w = max_width.min(width).max(1);
    let h = ((height as f64 * w as f64 / width.max(1) as f64).round() as u32).max(1);
    let settings = RenderSettings { width: w, height: h, samples: 1, count_work: false, stride: 1 };
    let mut image_png = Vec::new();
    let mut costs = Vec::new();
    for &kind in kinds {
        let (world, _) = build(scene, kind)?;
        let out = Renderer::new(scene, &world).size(w, h).samples(1).record_cost(true).render()?;
        if image_png.is_empty() {
            let film = render(scene, &world, RenderSettings { samples, ..settings })?.film;
            image_png = png(film.to_srgb8(), w, h)?;
        }
        costs.push((kind.name().to_owned(), out.cost.expect("the cost was recorded")));
    }
    let max = costs.iter().map(|(_, c)| c.max()).max().unwrap_or(0);
    let scale = HeatmapScale::log(max);
    let heatmaps = costs
        .iter()
        .map(|(name, cost)| {
            let img = Heatmap::new(w, h, cost.values(), scale).to_rgb8();
            let (iw, ih) = (img.width(), img.height());
            Ok((name.clone(), png(img.into_raw(), iw, ih)?))
        })
        .collect::<Result<_, LabError>>()?;
    Ok(ReportPictures { image_png, heatmaps, scale, width: w, height: h })
}

/// Encodes 8-bit RGB pixels as PNG.
pub fn png(rgb: Vec<u8>, width: u32, height: u32) -> Result<Vec<u8>, LabError> {
    let img = image::RgbImage::from_raw(width, height, rgb).expect("a film holds width x height pixels");
    let mut bytes = std::io::Cursor::new(Vec::new());
    img.write_to(&mut bytes, image::ImageFormat::Png)
        .map_err(|error| OutputError::Encode { path: "report.png".into(), error })?;
    Ok(bytes.into_inner())
}

/// The start of a page titled `title` (escaped here), up to its `<h1>`.
pub fn head(title: &str) -> String {
    let title = escape(title);
    format!(
        "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n<title>{title}</title>\n<style>\n\
         body {{ font: 15px/1.4 system-ui, sans-serif; margin: 2em; color: #222; }}\n\
         table {{ border-collapse: collapse; margin: 1em 0; }}\n\
         th, td {{ padding: 0.2em 0.7em; border-bottom: 1px solid #ddd; text-align: right; }}\n\
         th:first-child, td:first-child {{ text-align: left; }}\n\
         .pictures {{ display: flex; flex-wrap: wrap; gap: 1em; }}\n\
         figure {{ margin: 0; }} figcaption {{ text-align: center; font-size: 90%; }}\n\
         .differ, .no {{ color: #b00; font-weight: bold; }}\n.yes {{ color: #070; }}\n\
         </style>\n</head>\n<body>\n<h1>{title}</h1>\n"
    )
}

/// The end of a page.
pub const TAIL: &str = "</body>\n</html>\n";

/// An SVG document as a page's inline element: the XML declaration, if any, belongs to a file.
pub fn inline_svg(svg: &str) -> &str {
    svg.trim_start_matches(|ch| ch != '<').split_once("?>").map_or(svg, |(_, rest)| rest)
}

/// The pictures as one row of figures: the image, then each heatmap under its structure's name.
pub fn pictures(p: &mut String, pictures: &ReportPictures) {
    let _ = writeln!(p, "<div class=\"pictures\">");
    picture(p, "image", &pictures.image_png, "the image");
    for (name, bytes) in &pictures.heatmaps {
        picture(p, "heatmap", bytes, name);
    }
    let _ = writeln!(p, "</div>");
}

fn picture(p: &mut String, class: &str, png: &[u8], caption: &str) {
    let _ = writeln!(
        p,
        "<figure class=\"{class}\"><img alt=\"{0}\" src=\"data:image/png;base64,{1}\"><figcaption>{0}</figcaption></figure>",
        escape(caption),
        base64(png)
    );
}

/// Writes `page` into `dir` (created if needed) as `index.html`, atomically; returns its path.
pub fn write_page(dir: &Path, page: &str) -> Result<PathBuf, LabError> {
    std::fs::create_dir_all(dir).map_err(|source| LabError::CreateDir { path: dir.to_owned(), source })?;
    let path = dir.join("index.html");
    englobe_render::output::write_atomically(&path, |w| {
        w.write_all(page.as_bytes()).map_err(|error| OutputError::Io { path: path.clone(), error })
    })?;
    Ok(path)
}

/// `s` with HTML's special characters escaped.
pub fn escape(s: &str) -> String {
    s.replace('&', "&amp;").replace('<', "&lt;").replace('>', "&gt;").replace('"', "&quot;")
}

/// Standard base64 with padding (RFC 4648), for the data URIs.
pub fn base64(bytes: &[u8]) -> String {
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

/// Checks of a page's structure that every report's tests share: a whole document, every picture
/// inside it, no script, no link outside it.
#[cfg(test)]
pub fn assert_self_contained(page: &str, images: usize) {
    assert!(page.starts_with("<!DOCTYPE html>") && page.trim_end().ends_with("</html>"));
    assert_eq!(page.matches("<img ").count(), images);
    assert_eq!(page.matches("src=\"data:image/png;base64,").count(), images, "every picture is inside the page");
    assert_eq!(page.matches("http").count(), page.matches("http://www.w3.org/").count(), "no link but namespaces");
    assert!(!page.contains("<script"), "no script");
    assert!(!page.contains("<?xml"));
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn base64_is_rfc_4648() {
        for (plain, coded) in [("", ""), ("f", "Zg=="), ("fo", "Zm8="), ("foo", "Zm9v"), ("foobar", "Zm9vYmFy")] {
            assert_eq!(base64(plain.as_bytes()), coded);
        }
    }

    #[test]
    fn the_head_escapes_its_title() {
        let h = head("a <b> & \"c\"");
        assert!(h.contains("<title>a &lt;b&gt; &amp; &quot;c&quot;</title>"), "{h}");
        assert!(h.ends_with("<h1>a &lt;b&gt; &amp; &quot;c&quot;</h1>\n"));
    }
}
