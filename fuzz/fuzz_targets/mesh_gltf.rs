//! Any bytes given as a glTF file (JSON, or the binary GLB container when they start with its
//! magic) either load to a valid mesh (finite positions and texture coordinates, in both sets)
//! or are refused with an error naming the file; never a panic, never an absurd allocation.
#![no_main]

use englobe_scene::mesh::{MeshFormat, load_mesh_bytes};
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let (path, format) = if data.starts_with(b"glTF") {
        (std::path::Path::new("fuzz.glb"), MeshFormat::Glb)
    } else {
        (std::path::Path::new("fuzz.gltf"), MeshFormat::Gltf)
    };
    let name = path.to_str().unwrap();
    match load_mesh_bytes(path, format, data.to_vec()) {
        Ok(loaded) => {
            assert!(loaded.mesh.positions().iter().all(|p| p.is_finite()));
            // Both texture coordinate sets (the second is read when a material samples it).
            for set in 0..2 {
                assert!(loaded.mesh.uv_set(set).is_none_or(|uvs| uvs.iter().all(|uv| uv.is_finite())));
            }
        }
        // The error names the file, or the buffer file it refers to.
        Err(e) => {
            let shown = e.to_string();
            assert!(shown.contains(name) || shown.contains(".bin"), "an error that names no file: {shown}");
        }
    }
});
