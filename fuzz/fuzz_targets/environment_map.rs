//! Any bytes given as an environment map (OpenEXR or Radiance HDR) either decode to a map of the
//! size it says, every pixel finite and at least 0, or are refused with an error naming the file;
//! never a panic, never an absurd allocation.
#![no_main]

use englobe_scene::environment::decode_environment_map;
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let path = std::path::Path::new("fuzz.exr");
    match decode_environment_map(data, path) {
        Ok(map) => {
            assert_eq!(map.pixels.len(), map.width as usize * map.height as usize);
            assert!(map.pixels.iter().all(|p| p.is_finite() && p.min_element() >= 0.0));
        }
        Err(e) => assert!(e.to_string().contains("fuzz.exr"), "an error that does not name the file: {e}"),
    }
});
