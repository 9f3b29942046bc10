//! Texture images (PNG, JPEG, OpenEXR): decoded within the size limits or refused, never a panic.
#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    if let Ok(image) = englobe_scene::texture::decode_image(data) {
        assert!(image.width() as u64 * image.height() as u64 <= englobe_scene::texture::MAX_TEXTURE_PIXELS);
    }
});
