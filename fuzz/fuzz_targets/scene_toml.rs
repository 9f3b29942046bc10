//! Any text given as a scene file is either a valid scene or a located error; never a panic.
#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    if let Ok(text) = std::str::from_utf8(data) {
        if let Err(e) = englobe_scene::parse_scene(text, "fuzz.toml".as_ref()) {
            let shown = e.to_string();
            assert!(shown.starts_with("fuzz.toml:"), "an error without a place: {shown}");
        }
    }
});
