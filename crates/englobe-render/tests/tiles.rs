//! A render in pieces is the render: windows hold exactly the full render's pixel values, for
//! both integrators and any window, and tiles written to files and assembled give the same image
//! bytes as one render, in PNG and EXR.

use englobe::AccelKind;
use englobe_render::tile::assemble::{Tile, assemble};
use englobe_render::tile::file::{TileHeader, VERSION, read_tile, write_tile};
use englobe_render::{DEFAULT_SCENE, Film, PixelWindow, Renderer, TileSpec, build_world, write_image};
use englobe_scene::{IntegratorKind, Scene, parse_scene};

fn scene(integrator: IntegratorKind) -> Scene {
    let mut s = parse_scene(DEFAULT_SCENE, "default.toml".as_ref()).unwrap();
    s.image.width = 45;
    s.image.height = 37;
    s.image.samples = 3;
    s.image.integrator = integrator;
    s
}

fn render(s: &Scene, window: Option<PixelWindow>) -> Film {
    let world = build_world(s, AccelKind::BvhWide).unwrap();
    let r = Renderer::new(s, &world);
    let out = match window {
        Some(w) => r.window(w).render().unwrap(),
        None => r.render().unwrap(),
    };
    assert!(out.complete);
    assert_eq!(out.window, window.unwrap_or(PixelWindow::full(45, 37)));
    out.film
}

fn bits(f: &Film) -> Vec<[u32; 3]> {
    f.pixels().iter().map(|p| p.to_array().map(f32::to_bits)).collect()
}

#[test]
fn a_window_holds_the_full_renders_values() {
    for integrator in [IntegratorKind::Whitted, IntegratorKind::Path] {
        let s = scene(integrator);
        let full = render(&s, None);
        for w in [PixelWindow { x0: 3, x1: 40, y0: 5, y1: 36 }, PixelWindow { x0: 44, x1: 45, y0: 0, y1: 37 }] {
            let part = render(&s, Some(w));
            assert_eq!((part.width(), part.height()), (w.width(), w.height()));
            for y in 0..w.height() {
                for x in 0..w.width() {
                    let (a, b) = (part.get(x, y), full.get(w.x0 + x, w.y0 + y));
                    assert_eq!(
                        a.to_array().map(f32::to_bits),
                        b.to_array().map(f32::to_bits),
                        "{integrator:?} {x},{y} of {w}"
                    );
                }
            }
        }
    }
}

#[test]
fn a_window_outside_the_image_is_refused() {
    let s = scene(IntegratorKind::Whitted);
    let world = build_world(&s, AccelKind::None).unwrap();
    let e = Renderer::new(&s, &world).window(PixelWindow { x0: 0, x1: 46, y0: 0, y1: 1 }).render().unwrap_err();
    assert!(e.to_string().contains("outside the 45x37 image"), "{e}");
}

#[test]
fn tiles_on_disk_assemble_to_the_same_bytes() {
    let dir = tempfile::tempdir().unwrap();
    let s = scene(IntegratorKind::Path);
    let full = render(&s, None);
    for ext in ["png", "exr"] {
        let one = dir.path().join(format!("one.{ext}"));
        write_image(&full, &one).unwrap();
        for count in [1, 4, 7] {
            let tiles: Vec<Tile> = TileSpec::all(count)
                .map(|spec| {
                    let window = spec.window(45, 37).unwrap();
                    let header = TileHeader {
                        full_width: 45,
                        full_height: 37,
                        window,
                        scene_digest: "0".repeat(64),
                        version: VERSION.into(),
                        tile: Some(spec),
                        output: Default::default(),
                    };
                    let path = dir.path().join(format!("tile-{}-{count}.exr", spec.index));
                    write_tile(&path, &header, &render(&s, Some(window))).unwrap();
                    let (header, film) = read_tile(&path).unwrap();
                    Tile { path, header, film }
                })
                .collect();
            let film = assemble(&tiles).unwrap();
            assert_eq!(bits(&film), bits(&full));
            let assembled = dir.path().join(format!("assembled-{count}.{ext}"));
            write_image(&film, &assembled).unwrap();
            assert_eq!(std::fs::read(&assembled).unwrap(), std::fs::read(&one).unwrap(), "{count} tiles, {ext}");
        }
    }
}
