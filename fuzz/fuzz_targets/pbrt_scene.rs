//! Any text given as a pbrt scene is either a scene or an error at a file, line and column
//! (strict or not); never a panic, never an absurd allocation.
//!
//! The scene is said to live in a folder that does not exist, so that the relative `Include`s
//! and `plymesh` files of the input (the corpus is seeded with pbrt scenes) never reach real
//! files. The same body runs in englobe-scene's `tests/pbrt_scenes.rs` on cut and scrambled
//! copies of the Cornell box.
#![no_main]

use libfuzzer_sys::fuzz_target;

const PATH: &str = "no-such-folder/fuzz.pbrt";

fuzz_target!(|data: &[u8]| {
    if let Ok(text) = std::str::from_utf8(data) {
        for strict in [false, true] {
            match englobe_scene::pbrt::parse(text, PATH.as_ref(), strict) {
                Ok(scene) => assert!(scene.image.width >= 1 && scene.image.height >= 1),
                Err(e) => {
                    let shown = e.to_string();
                    let first = shown.lines().next().unwrap_or("");
                    let mut parts = first.splitn(4, ':');
                    let (file, line, column) = (parts.next(), parts.next(), parts.next());
                    assert!(
                        file.is_some_and(|f| !f.is_empty())
                            && line.is_some_and(|l| l.parse::<u32>().is_ok())
                            && column.is_some_and(|c| c.parse::<u32>().is_ok()),
                        "an error without a place: {shown}"
                    );
                }
            }
        }
    }
});
