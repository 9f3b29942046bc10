//! MTL material libraries: every statement and texture option checked, and each material mapped
//! onto englobe's materials, never a panic.
#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    if let Ok(text) = std::str::from_utf8(data) {
        let _ = englobe_scene::mesh::check_mtl_text(std::path::Path::new("fuzz.mtl"), text);
    }
});
