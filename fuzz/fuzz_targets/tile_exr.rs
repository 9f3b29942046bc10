//! Any bytes given as a tile either read to a tile whose window lies inside its image and whose
//! film has the window's size, or are refused with an error naming the file; never a panic.
#![no_main]

use englobe_render::tile::file::read_tile_from;
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let path = std::path::Path::new("fuzz.exr");
    match read_tile_from(std::io::Cursor::new(data), path) {
        Ok((header, film)) => {
            let w = header.window;
            assert!(w.x0 < w.x1 && w.y0 < w.y1 && w.x1 <= header.full_width && w.y1 <= header.full_height);
            assert_eq!((film.width(), film.height()), (w.width(), w.height()));
        }
        Err(e) => assert!(e.to_string().contains("fuzz.exr"), "an error that does not name the file: {e}"),
    }
});
