//! PLY files whose faces come as triangle strips (a `tristrips` element, `-1` between strips, as
//! older scanned-model archives store them), and PLY files with no faces at all.

use englobe_scene::mesh::{MeshErrorKind, MeshFormat, load_mesh_bytes};

/// A 2 x 4 grid of vertices in the z = 0 plane, `x` along the strip, with `strip` as its list.
fn grid(strip: &str, count: usize) -> Vec<u8> {
    let mut text =
        String::from("ply\nformat ascii 1.0\nelement vertex 8\nproperty float x\nproperty float y\nproperty float z\n");
    text += "element tristrips 1\nproperty list int int vertex_indices\nend_header\n";
    for i in 0..4 {
        text += &format!("{i} 0 0\n{i} 1 0\n");
    }
    text += &format!("{count} {strip}\n");
    text.into_bytes()
}

fn load(bytes: Vec<u8>) -> Result<englobe_scene::mesh::LoadedMesh, englobe_scene::mesh::MeshFileError> {
    load_mesh_bytes("strips.ply".as_ref(), MeshFormat::Ply, bytes)
}

#[test]
fn a_strip_of_n_vertices_gives_n_minus_2_triangles_of_one_winding() {
    let mesh = load(grid("0 1 2 3 4 5 6 7", 8)).unwrap().mesh;
    assert_eq!(mesh.len(), 6);
    assert_eq!(mesh.triangles()[0], [0, 1, 2]);
    assert_eq!(mesh.triangles()[1], [2, 1, 3], "every second triangle swaps its first two vertices");
    let first = mesh.geometric_normal(0);
    for i in 0..mesh.len() as u32 {
        assert!(mesh.geometric_normal(i).dot(first) > 0.99, "triangle {i} faces the other way");
    }
}

#[test]
fn minus_one_restarts_and_repeated_vertices_are_joins() {
    // Two strips of 4 vertices: 2 + 2 triangles; then a join with a repeated vertex, dropped.
    let mesh = load(grid("0 1 2 3 -1 4 5 6 7", 9)).unwrap().mesh;
    assert_eq!(mesh.len(), 4);
    let mesh = load(grid("0 1 2 3 3 4 4 5 6 7", 10)).unwrap().mesh;
    assert_eq!(mesh.len(), 4, "of 8, the four triangles that repeat 3 or 4 are the joins");
    assert_eq!(mesh.triangles(), [[0, 1, 2], [2, 1, 3], [4, 5, 6], [6, 5, 7]]);
}

#[test]
fn a_bad_strip_index_is_refused_with_its_line() {
    let e = load(grid("0 1 2 9", 4)).unwrap_err();
    assert!(matches!(e.kind, MeshErrorKind::IndexOutOfRange { .. }), "{e}");
    assert_eq!(e.line_number(), Some(18), "{e}");
    let e = load(grid("0 1 2 -2", 4)).unwrap_err();
    assert!(e.to_string().contains("index -2 is out of range: 8 defined (-1 ends a strip)"), "{e}");
}

#[test]
fn a_file_with_no_faces_says_so() {
    let text = "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\nend_header\n0 0 0\n1 0 0\n0 1 0\n";
    let e = load(text.as_bytes().to_vec()).unwrap_err();
    assert!(matches!(e.kind, MeshErrorKind::NoTriangles(_)), "{e}");
    assert!(
        e.to_string().contains("no `face` or `tristrips` element, so no surface to draw; its elements: vertex (3)"),
        "{e}"
    );
}

#[test]
fn the_shared_bunny_as_strips_has_every_triangle() {
    // The bunny's faces, rewritten as one strip per triangle (with restarts): the same count.
    let dir = englobe_scene::shared_data::shared_meshes_or_panic(env!("CARGO_MANIFEST_DIR").as_ref());
    let bunny = englobe_scene::mesh::load_mesh_file(&dir.join("bunny/bun_zipper.ply")).unwrap().mesh;
    let mut text = format!(
        "ply\nformat ascii 1.0\nelement vertex {}\nproperty float x\nproperty float y\nproperty float z\n",
        bunny.positions().len()
    );
    text += "element tristrips 1\nproperty list int int vertex_indices\nend_header\n";
    for p in bunny.positions() {
        text += &format!("{} {} {}\n", p.x, p.y, p.z);
    }
    let strip: Vec<String> = bunny.triangles().iter().map(|t| format!("{} {} {} -1", t[0], t[1], t[2])).collect();
    text += &format!("{} {}\n", bunny.len() * 4, strip.join(" "));
    let strips = load(text.into_bytes()).unwrap().mesh;
    assert_eq!(strips.len(), 69_451);
    assert_eq!(strips.triangles(), bunny.triangles());
}
