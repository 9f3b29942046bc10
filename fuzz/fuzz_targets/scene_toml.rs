//! Any text given as a scene file is either a valid scene or a located error; never a panic.
//!
//! The scene is said to live in a folder that does not exist, so that mesh paths in the input
//! (the corpus is seeded with the project's scenes) never reach real files: loading a real mesh
//! is slow, and the mesh loaders have targets of their own.
#![no_main]

use libfuzzer_sys::fuzz_target;

const PATH: &str = "no-such-folder/fuzz.toml";

fuzz_target!(|data: &[u8]| {
    if let Ok(text) = std::str::from_utf8(data) {
        if let Err(e) = englobe_scene::parse_scene(text, PATH.as_ref()) {
            let shown = e.to_string();
            assert!(shown.starts_with(PATH), "an error without a place: {shown}");
        }
    }
});
