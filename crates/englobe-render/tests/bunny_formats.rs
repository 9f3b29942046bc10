//! The Stanford bunny from its three files (the OBJ, the original ASCII PLY, the binary PLY): the
//! same 69 451 triangles, and renders that agree.
//!
//! The two PLY files hold the same triangles bit for bit, in a different order, with different
//! vertex numbering, and each triangle may start from a different corner: their renders must be
//! byte-identical. The OBJ holds the same mesh with every coordinate rounded to six decimals
//! (up to 5e-7 away from the PLY's) and every triangle wound the other way, so its render may differ
//! where those last digits move a silhouette or a shadow edge across a pixel centre, and nowhere
//! else; the test bounds that.

use std::collections::HashSet;
use std::path::{Path, PathBuf};

use englobe::AccelKind;
use englobe_render::{Renderer, build_world};
use englobe_scene::mesh::load_mesh_file;
use englobe_scene::parse_scene;
use englobe_scene::shared_data::shared_meshes_or_panic;

fn meshes() -> PathBuf {
    shared_meshes_or_panic(Path::new(env!("CARGO_MANIFEST_DIR")))
}

/// A small view of the bunny with one light, rendered to 8-bit sRGB.
fn render(file: &str) -> Vec<u8> {
    let text = format!(
        r#"
        [image]
        width = 64
        height = 64
        background = [0.3, 0.4, 0.5]
        ambient = [0.1, 0.1, 0.1]
        [camera]
        position = [0.05, 0.15, 0.42]
        look_at = [-0.017, 0.11, 0.0]
        fov = 30
        [[directional_light]]
        direction = [-0.5, -1.0, -0.7]
        [[mesh]]
        path = "{file}"
        "#
    );
    let scene = parse_scene(&text, &meshes().join("bunny.toml")).unwrap_or_else(|e| panic!("{e}"));
    // Every structure draws brute force's image (tests/accel_agreement.rs in the library); the
    // binned-SAH BVH renders it a thousand times sooner.
    let world = build_world(&scene, AccelKind::BvhSah).unwrap();
    Renderer::new(&scene, &world).render().unwrap().film.to_srgb8()
}

/// Each triangle as its three corners, starting from the smallest, winding kept.
fn triangle_set(file: &str, reverse: bool) -> HashSet<[[u32; 3]; 3]> {
    let m = load_mesh_file(&meshes().join(file)).unwrap().mesh;
    m.triangles()
        .iter()
        .map(|t| {
            let mut c = t.map(|i| m.positions()[i as usize].to_array().map(f32::to_bits));
            if reverse {
                c.reverse();
            }
            let first = (0..3).min_by_key(|&k| c[k]).unwrap();
            c.rotate_left(first);
            c
        })
        .collect()
}

#[test]
fn the_three_bunny_files_hold_the_same_triangles() {
    let ascii = triangle_set("bunny/bun_zipper.ply", false);
    assert_eq!(ascii.len(), 69_451);
    assert_eq!(triangle_set("bunny/bun_zipper_binary.ply", false), ascii, "the PLY files differ");
    let obj = load_mesh_file(&meshes().join("bunny/stanford-bunny.obj")).unwrap().mesh;
    let ply = load_mesh_file(&meshes().join("bunny/bun_zipper.ply")).unwrap().mesh;
    assert_eq!(obj.len(), 69_451);
    // Triangle by triangle in the same order, wound the other way, corners rounded to six
    // decimals (the OBJ loader numbers vertices in order of first use, so indices differ).
    let mut worst = 0.0f32;
    for (a, b) in obj.triangles().iter().zip(ply.triangles()) {
        for k in 0..3 {
            let d = obj.positions()[a[2 - k] as usize] - ply.positions()[b[k] as usize];
            worst = worst.max(d.abs().max_element());
        }
    }
    assert!(worst <= 5.01e-7, "the OBJ strays {worst} from the PLY");
}

#[test]
fn the_bunny_renders_the_same_from_every_file() {
    let ascii = render("bunny/bun_zipper.ply");
    let binary = render("bunny/bun_zipper_binary.ply");
    assert!(ascii.iter().any(|&b| b != ascii[0]), "the picture is blank");
    assert!(ascii == binary, "the two PLY files render differently");
    let obj = render("bunny/stanford-bunny.obj");
    let pixels = ascii.len() / 3;
    let differing: Vec<usize> = (0..pixels).filter(|&p| ascii[3 * p..3 * p + 3] != obj[3 * p..3 * p + 3]).collect();
    let off_by_more_than_one = (0..ascii.len()).filter(|&i| ascii[i].abs_diff(obj[i]) > 1).count();
    println!(
        "OBJ vs PLY: {} of {pixels} pixels differ, {off_by_more_than_one} values by more than one level",
        differing.len()
    );
    assert!(differing.len() * 100 <= pixels, "{} of {pixels} pixels differ", differing.len());
}
