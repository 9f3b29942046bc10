//! Any bytes given as a OBJ file either load to a valid mesh or are refused with an error
//! naming the file; never a panic, never an absurd allocation.
#![no_main]

use englobe_scene::mesh::{MeshFormat, load_mesh_bytes};
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let path = std::path::Path::new("fuzz.obj");
    match load_mesh_bytes(path, MeshFormat::Obj, data.to_vec()) {
        Ok(loaded) => assert!(loaded.mesh.positions().iter().all(|p| p.is_finite())),
        Err(e) => assert!(e.to_string().contains("fuzz.obj"), "an error that does not name the file: {e}"),
    }
});
