//! Hostile mesh files, each written by the test byte for byte: every one is refused with a typed
//! error that names the file and the line, byte or JSON path, or (CRLF headers, big-endian data)
//! loads correctly. Nothing panics and nothing allocates what the file cannot back.

use std::path::{Path, PathBuf};

use englobe_scene::mesh::{LoadedMesh, MeshErrorKind, MeshFileError, Position, load_mesh_file};

fn write(dir: &Path, name: &str, bytes: &[u8]) -> PathBuf {
    let p = dir.join(name);
    std::fs::write(&p, bytes).unwrap();
    p
}

fn load(dir: &Path, name: &str, bytes: &[u8]) -> Result<LoadedMesh, MeshFileError> {
    let p = write(dir, name, bytes);
    let result = load_mesh_file(&p);
    if let Err(e) = &result {
        assert!(e.to_string().starts_with(&p.display().to_string()), "does not name the file: {e}");
    }
    result
}

fn refused(dir: &Path, name: &str, bytes: &[u8]) -> MeshFileError {
    match load(dir, name, bytes) {
        Ok(m) => panic!("{name} loaded with {} triangles", m.mesh.len()),
        Err(e) => e,
    }
}

const TRIANGLE: &str = "v 0 0 0\nv 1 0 0\nv 0 1 0\n";

#[test]
fn obj_bad_indices_and_numbers_are_refused_at_their_line() {
    let dir = tempfile::tempdir().unwrap();
    for (face, what) in [
        ("f 0 1 2", "zero"),
        ("f -99 1 2", "negative beyond"),
        ("f 1 2 999999", "past the end"),
        ("f 1 2 18446744073709551616", "does not fit 64 bits"),
        ("f 1 2 9223372036854775807", "largest i64"),
        ("f 1 2 -9223372036854775808", "smallest i64"),
    ] {
        let e = refused(dir.path(), "m.obj", format!("{TRIANGLE}{face}\n").as_bytes());
        assert_eq!(e.line_number(), Some(4), "{what}: {e}");
        assert!(matches!(e.kind, MeshErrorKind::IndexOutOfRange { what: "vertex", .. }), "{what}: {e}");
    }
    for (line, expect_finite) in [("v nan 0 0", false), ("v 1e999 0 0", false), ("v 0 -inf 0", false), ("v 1 2", true)]
    {
        let e = refused(dir.path(), "m.obj", format!("# header\n{line}\n{TRIANGLE}f 2 3 4\n").as_bytes());
        assert_eq!(e.line_number(), Some(2), "{line}: {e}");
        match e.kind {
            MeshErrorKind::NonFinite { .. } => assert!(!expect_finite, "{line}: {e}"),
            MeshErrorKind::Arity { found: 2, .. } => assert!(expect_finite, "{line}: {e}"),
            _ => panic!("{line}: unexpected {e}"),
        }
    }
    let e = refused(dir.path(), "m.obj", format!("{TRIANGLE}f 1 2 3x\n").as_bytes());
    assert!(matches!(e.kind, MeshErrorKind::BadNumber { .. }) && e.line_number() == Some(4), "{e}");
    let e = refused(dir.path(), "m.obj", b"v 1 2 3\nv 1.#IND 0 0\n");
    assert!(matches!(e.kind, MeshErrorKind::BadNumber { .. }) && e.line_number() == Some(2), "{e}");
}

#[test]
fn obj_with_a_two_number_colour_in_its_mtl_is_refused_at_the_mtl_line() {
    // `tobj` 4.0.5 panics on this MTL line; englobe's check must refuse it first.
    let dir = tempfile::tempdir().unwrap();
    let mtl = write(dir.path(), "m.mtl", b"newmtl red\nKd 0.5 0.5\n");
    let obj = write(dir.path(), "m.obj", format!("mtllib m.mtl\n{TRIANGLE}usemtl red\nf 1 2 3\n").as_bytes());
    let e = load_mesh_file(&obj).unwrap_err();
    assert_eq!(e.path, mtl, "the error names the material library: {e}");
    assert_eq!(e.line_number(), Some(2));
    // Two numbers are none of the colour forms the MTL specification allows (`r [g b]`, `xyz`,
    // `spectral`): the message says which statement and what it found.
    assert!(matches!(&e.kind, MeshErrorKind::Malformed(m) if m.contains("`Kd`") && m.contains("found two")), "{e}");
}

#[test]
fn obj_materials_map_per_triangle() {
    let dir = tempfile::tempdir().unwrap();
    write(dir.path(), "m.mtl", b"newmtl red\nKd 1 0 0\nnewmtl lamp\nKd 1 1 1\nKe 5 5 5\n");
    let text = format!("mtllib m.mtl\n{TRIANGLE}v 1 1 0\nf 1 2 3\nusemtl lamp\nf 2 4 3\nusemtl red\nf -4 -3 -2\n");
    let m = load(dir.path(), "m.obj", text.as_bytes()).unwrap();
    assert_eq!(m.mesh.len(), 3);
    let names: Vec<&str> = m.materials.iter().map(|(n, _)| n.as_str()).collect();
    assert_eq!(names, ["red", "lamp"]);
    assert_eq!(m.triangle_materials, Some(vec![englobe_scene::mesh::NO_MATERIAL, 1, 0]));
    assert_eq!(m.materials[1].1.emission, englobe::Vec3::splat(5.0));
}

/// A PLY header for `vertices` vertices (x y z float) and `faces` faces, then `body`.
fn ply(format: &str, vertices: u64, faces: u64, count_type: &str, body: &[u8]) -> Vec<u8> {
    let mut out = format!(
        "ply\nformat {format} 1.0\nelement vertex {vertices}\nproperty float x\nproperty float y\nproperty float z\n\
         element face {faces}\nproperty list {count_type} int vertex_indices\nend_header\n"
    )
    .into_bytes();
    out.extend_from_slice(body);
    out
}

fn binary_body(big_endian: bool, count: &[u8]) -> Vec<u8> {
    let mut body = Vec::new();
    let f = |x: f32| if big_endian { x.to_be_bytes() } else { x.to_le_bytes() };
    let i = |x: i32| if big_endian { x.to_be_bytes() } else { x.to_le_bytes() };
    for v in [[0.0f32, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]] {
        v.iter().for_each(|&c| body.extend(f(c)));
    }
    body.extend_from_slice(count);
    [0, 1, 2].iter().for_each(|&k| body.extend(i(k)));
    body
}

#[test]
fn ply_absurd_counts_are_refused_before_allocating() {
    let dir = tempfile::tempdir().unwrap();
    for format in ["ascii", "binary_little_endian", "binary_big_endian"] {
        let mut file = ply(format, 4_294_967_295, 1, "uchar", b"");
        file.resize(100.max(file.len()), b'0');
        let e = refused(dir.path(), "big.ply", &file);
        assert_eq!(e.line_number(), Some(3), "{format}: {e}");
        assert!(matches!(e.kind, MeshErrorKind::CountTooLarge { count: 4_294_967_295, .. }), "{format}: {e}");
    }
    let e =
        refused(dir.path(), "huge.ply", &ply("binary_little_endian", 3, u64::MAX, "uchar", &binary_body(false, &[3])));
    assert!(matches!(e.kind, MeshErrorKind::CountTooLarge { .. }) && e.line_number() == Some(7), "{e}");
}

#[test]
fn ply_bad_list_counts_are_refused_at_their_byte_or_line() {
    let dir = tempfile::tempdir().unwrap();
    // Negative count in a signed type, and a count far beyond the bytes left.
    let e = refused(dir.path(), "neg.ply", &ply("binary_little_endian", 3, 1, "char", &binary_body(false, &[0xFF])));
    let header_len = ply("binary_little_endian", 3, 1, "char", b"").len() as u64;
    assert_eq!(e.at, Some(Position::Byte(header_len + 36 + 1)), "{e}");
    assert!(matches!(e.kind, MeshErrorKind::Malformed(_)), "{e}");
    let big = 1_000_000_000u32.to_le_bytes();
    let e = refused(dir.path(), "over.ply", &ply("binary_little_endian", 3, 1, "uint", &binary_body(false, &big)));
    assert!(matches!(e.kind, MeshErrorKind::CountTooLarge { count: 1_000_000_000, .. }), "{e}");
    assert!(e.byte_offset().is_some(), "{e}");
    let ascii = |face: &str| ply("ascii", 3, 1, "uchar", format!("0 0 0\n1 0 0\n0 1 0\n{face}\n").as_bytes());
    let e = refused(dir.path(), "neg.ply", &ascii("-1 0 1 2"));
    assert_eq!(e.line_number(), Some(13), "{e}");
    let e = refused(dir.path(), "over.ply", &ascii("200 0 1 2"));
    assert!(matches!(e.kind, MeshErrorKind::CountTooLarge { .. }) && e.line_number() == Some(13), "{e}");
    let e = refused(dir.path(), "idx.ply", &ascii("3 0 1 3"));
    assert!(matches!(e.kind, MeshErrorKind::IndexOutOfRange { .. }) && e.line_number() == Some(13), "{e}");
    let e = refused(dir.path(), "num.ply", &ply("ascii", 3, 1, "uchar", b"0 0 0\n1 zero 0\n0 1 0\n3 0 1 2\n"));
    assert!(matches!(e.kind, MeshErrorKind::BadNumber { .. }) && e.line_number() == Some(11), "{e}");
    let e = refused(dir.path(), "nan.ply", &ply("ascii", 3, 1, "uchar", b"0 0 0\n1 nan 0\n0 1 0\n3 0 1 2\n"));
    assert!(matches!(e.kind, MeshErrorKind::NonFinite { .. }) && e.line_number() == Some(11), "{e}");
}

#[test]
fn ply_truncated_bodies_are_refused() {
    let dir = tempfile::tempdir().unwrap();
    let full = ply("binary_big_endian", 3, 1, "uchar", &binary_body(true, &[3]));
    for cut in [1, 5, 13, 20] {
        let e = refused(dir.path(), "cut.ply", &full[..full.len() - cut]);
        assert!(matches!(e.kind, MeshErrorKind::Truncated(_) | MeshErrorKind::CountTooLarge { .. }), "{e}");
        assert!(e.byte_offset().is_some() || e.line_number().is_some(), "{e}");
    }
    // Too short for the face it declares: refused from the header's counts alone.
    let e = refused(dir.path(), "cut.ply", &ply("ascii", 3, 1, "uchar", b"0 0 0\n1 0 0\n0 1 0\n"));
    assert!(matches!(e.kind, MeshErrorKind::CountTooLarge { .. }) && e.line_number() == Some(7), "{e}");
    let e = refused(dir.path(), "cut.ply", &ply("ascii", 3, 2, "uchar", b"0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n"));
    assert!(matches!(e.kind, MeshErrorKind::Truncated(_)), "{e}");
    let e = refused(dir.path(), "cut.ply", &ply("ascii", 3, 1, "uchar", b"0 0 0\n1 0 0\n0 1\n3 0 1 2\n"));
    assert!(matches!(e.kind, MeshErrorKind::Truncated(_)) && e.line_number() == Some(12), "{e}");
}

#[test]
fn ply_crlf_and_big_endian_files_load_like_the_plain_ones() {
    let dir = tempfile::tempdir().unwrap();
    let little =
        load(dir.path(), "le.ply", &ply("binary_little_endian", 3, 1, "uchar", &binary_body(false, &[3]))).unwrap();
    let big = load(dir.path(), "be.ply", &ply("binary_big_endian", 3, 1, "uchar", &binary_body(true, &[3]))).unwrap();
    let ascii = String::from_utf8(ply("ascii", 3, 1, "uchar", b"0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n")).unwrap();
    let crlf = load(dir.path(), "crlf.ply", ascii.replace('\n', "\r\n").as_bytes()).unwrap();
    let mut crlf_header = ply("binary_big_endian", 3, 1, "uchar", b"");
    crlf_header = String::from_utf8(crlf_header).unwrap().replace('\n', "\r\n").into_bytes();
    crlf_header.extend(binary_body(true, &[3]));
    let crlf_binary = load(dir.path(), "crlf_be.ply", &crlf_header).unwrap();
    for m in [&big, &crlf, &crlf_binary] {
        assert_eq!(m.mesh.positions(), little.mesh.positions());
        assert_eq!(m.mesh.triangles(), little.mesh.triangles());
    }
    assert_eq!(little.mesh.triangles(), &[[0, 1, 2]]);
}

#[test]
fn text_files_without_a_final_newline_or_with_a_byte_order_mark_load() {
    let dir = tempfile::tempdir().unwrap();
    let m = load(dir.path(), "tight.ply", &ply("ascii", 3, 1, "uchar", b"0 0 0\n1 0 0\n0 1 0\n3 0 1 2")).unwrap();
    assert_eq!(m.mesh.len(), 1);
    let m = load(dir.path(), "bom.obj", format!("\u{feff}{TRIANGLE}f 1 2 3").as_bytes()).unwrap();
    assert_eq!(m.mesh.positions().len(), 3);
    let e = refused(dir.path(), "latin1.obj", b"v 0 0 0\n# caf\xe9\n");
    assert_eq!(e.byte_offset(), Some(13), "{e}");
}

#[test]
fn ply_extra_properties_are_skipped_and_normals_kept() {
    let dir = tempfile::tempdir().unwrap();
    let text = "ply\nformat ascii 1.0\ncomment made by hand\nelement vertex 4\nproperty float x\nproperty float y\n\
                property float z\nproperty float confidence\nproperty float nx\nproperty float ny\nproperty float nz\n\
                property uchar red\nelement face 1\nproperty uchar flags\nproperty list uchar uint vertex_indices\n\
                property list uchar float texcoord\nelement edge 1\nproperty int a\nproperty int b\nend_header\n\
                0 0 0 0.5 0 0 1 255\n1 0 0 0.5 0 0 1 255\n1 1 0 0.5 0 0 1 255\n0 1 0 0.5 0 0 1 255\n\
                7 4 0 1 2 3 2 0.5 0.5\n0 1\n";
    let m = load(dir.path(), "q.ply", text.as_bytes()).unwrap();
    assert_eq!(m.mesh.triangles(), &[[0, 1, 2], [0, 2, 3]]);
    assert_eq!(m.mesh.normals().unwrap()[2], englobe::Vec3::Z);
}

/// A glTF document holding one triangle: positions (36 bytes) then three u16 indices, in
/// `tri.bin`; `patch` edits the JSON before it is written.
fn gltf_triangle(dir: &Path, indices: [u16; 3], patch: impl Fn(&mut serde_json::Value)) -> PathBuf {
    let mut bin = Vec::new();
    for c in [0.0f32, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0] {
        bin.extend(c.to_le_bytes());
    }
    indices.iter().for_each(|i| bin.extend(i.to_le_bytes()));
    bin.extend([0, 0]);
    write(dir, "tri.bin", &bin);
    let mut doc = serde_json::json!({
        "asset": {"version": "2.0"},
        "scene": 0,
        "scenes": [{"nodes": [0]}],
        "nodes": [{"mesh": 0, "translation": [0.0, 0.0, 5.0]}],
        "meshes": [{"primitives": [{"attributes": {"POSITION": 0}, "indices": 1}]}],
        "buffers": [{"uri": "tri.bin", "byteLength": 44}],
        "bufferViews": [
            {"buffer": 0, "byteOffset": 0, "byteLength": 36},
            {"buffer": 0, "byteOffset": 36, "byteLength": 6}
        ],
        "accessors": [
            {"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3", "min": [0, 0, 0], "max": [1, 1, 0]},
            {"bufferView": 1, "componentType": 5123, "count": 3, "type": "SCALAR"}
        ]
    });
    patch(&mut doc);
    write(dir, "tri.gltf", serde_json::to_string_pretty(&doc).unwrap().as_bytes())
}

fn json_at(e: &MeshFileError) -> String {
    match &e.at {
        Some(Position::Json(p)) => p.clone(),
        other => panic!("no JSON path in {e} ({other:?})"),
    }
}

#[test]
fn gltf_good_triangle_loads_with_its_node_transform() {
    let dir = tempfile::tempdir().unwrap();
    let m = load_mesh_file(&gltf_triangle(dir.path(), [0, 1, 2], |_| {})).unwrap();
    assert_eq!(m.mesh.triangles(), &[[0, 1, 2]]);
    assert_eq!(m.mesh.positions()[1], englobe::Vec3::new(1.0, 0.0, 5.0));
}

#[test]
fn gltf_lying_accessors_are_refused_with_their_json_path() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    type Patch = Box<dyn Fn(&mut serde_json::Value)>;
    let cases: Vec<(&str, Patch, &str)> = vec![
        ("count 0", Box::new(|j| j["accessors"][0]["count"] = 0.into()), "accessors[0].count"),
        ("count 2^62", Box::new(|j| j["accessors"][0]["count"] = (1u64 << 62).into()), "accessors[0].count"),
        ("index count 2^62", Box::new(|j| j["accessors"][1]["count"] = (1u64 << 62).into()), "accessors[1].count"),
        (
            "stride below the element",
            Box::new(|j| j["bufferViews"][0]["byteStride"] = 8.into()),
            "bufferViews[0].byteStride",
        ),
        ("past its view", Box::new(|j| j["accessors"][0]["byteOffset"] = 4.into()), "accessors[0].count"),
        ("view past its buffer", Box::new(|j| j["bufferViews"][1]["byteLength"] = 100.into()), "bufferViews[1]"),
        (
            "buffer longer than its file",
            Box::new(|j| j["buffers"][0]["byteLength"] = 400.into()),
            "buffers[0].byteLength",
        ),
        (
            "missing accessor",
            Box::new(|j| j["meshes"][0]["primitives"][0]["attributes"]["POSITION"] = 9.into()),
            "accessors[9]",
        ),
        ("missing view", Box::new(|j| j["accessors"][0]["bufferView"] = 7.into()), "accessors[0].bufferView"),
        ("missing mesh", Box::new(|j| j["nodes"][0]["mesh"] = 3.into()), "nodes[0].mesh"),
        ("cycle", Box::new(|j| j["nodes"][0]["children"] = serde_json::json!([0])), "nodes[0]"),
        (
            "draco",
            Box::new(|j| j["extensionsRequired"] = serde_json::json!(["KHR_draco_mesh_compression"])),
            "extensionsRequired[0]",
        ),
    ];
    for (what, patch, path) in cases {
        let file = gltf_triangle(d, [0, 1, 2], patch);
        let e = load_mesh_file(&file).expect_err(what);
        assert_eq!(json_at(&e), path, "{what}: {e}");
        assert!(e.to_string().starts_with(&file.display().to_string()), "{e}");
    }
    let e = load_mesh_file(&gltf_triangle(d, [0, 1, 3], |_| {})).unwrap_err();
    assert!(matches!(e.kind, MeshErrorKind::IndexOutOfRange { available: 3, .. }), "{e}");
    assert!(json_at(&e).starts_with("accessors[1] element 2 (byte 40 "), "{e}");
    let e = load_mesh_file(&write(d, "bad.gltf", b"{\n  \"asset\": {\"version\": \"2.0\"},\n  \"nodes\": [}\n"))
        .unwrap_err();
    assert_eq!(e.at, Some(Position::LineColumn(3, 13)), "{e}");
}

#[test]
fn glb_containers_that_lie_about_their_length_are_refused() {
    let dir = tempfile::tempdir().unwrap();
    let json = br#"{"asset":{"version":"2.0"}}  "#;
    let glb = |total: u32, chunk: u32| {
        let mut b = b"glTF".to_vec();
        b.extend(2u32.to_le_bytes());
        b.extend(total.to_le_bytes());
        b.extend(chunk.to_le_bytes());
        b.extend(b"JSON");
        b.extend(json);
        b
    };
    let honest = (12 + 8 + json.len()) as u32;
    for (total, chunk, byte) in [(4, json.len() as u32, 8), (honest + 10, json.len() as u32, 8), (honest, 1000, 12)] {
        let e = refused(dir.path(), "x.glb", &glb(total, chunk));
        assert_eq!(e.byte_offset(), Some(byte), "{e}");
    }
    // An honest container with no scene holds no triangles.
    let e = refused(dir.path(), "x.glb", &glb(honest, json.len() as u32));
    assert!(matches!(e.kind, MeshErrorKind::NoTriangles(_)), "{e}");
}

#[test]
fn unknown_missing_and_directory_paths_are_clear_errors() {
    let dir = tempfile::tempdir().unwrap();
    assert!(matches!(load_mesh_file(&dir.path().join("absent.obj")).unwrap_err().kind, MeshErrorKind::Io(_)));
    std::fs::create_dir(dir.path().join("folder.ply")).unwrap();
    let e = load_mesh_file(&dir.path().join("folder.ply")).unwrap_err();
    assert!(e.to_string().contains("directory"), "{e}");
    assert!(matches!(refused(dir.path(), "x.stl", b"solid").kind, MeshErrorKind::UnknownFormat(_)));
}

#[test]
fn a_gltf_buffer_that_cannot_be_read_is_named_with_the_gltf_file() {
    // Found by fuzzing: a buffer uri naming a missing file gave an error naming only that file.
    let dir = tempfile::tempdir().unwrap();
    let path = gltf_triangle(dir.path(), [0, 1, 2], |doc| doc["buffers"][0]["uri"] = "missing.lin".into());
    let e = load_mesh_file(&path).unwrap_err();
    assert_eq!(e.path, path);
    assert_eq!(json_at(&e), "buffers[0].uri");
    let MeshErrorKind::Referenced(inner) = &e.kind else { panic!("{e}") };
    assert!(matches!(inner.kind, MeshErrorKind::Io(_)), "{e}");
    assert_eq!(inner.path, dir.path().join("missing.lin"));
    let shown = e.to_string();
    assert!(
        shown.starts_with(&format!("{}: buffers[0].uri: ", path.display())) && shown.contains("missing.lin"),
        "{shown}"
    );
}
