//! Ctrl-C: the first one asks the render to stop (no new tile starts, tiles in flight finish), a
//! second one ends the process at once. Either way the exit code is 130 (128 + SIGINT), the
//! convention of shells, and no image is written, so an existing file is never replaced by a
//! partial one, unless `render --keep-partial` asked for the image of the sample passes done.

use std::sync::atomic::{AtomicBool, Ordering};

use anyhow::Context;

/// Exit code of a run stopped by Ctrl-C.
pub const INTERRUPTED_EXIT_CODE: u8 = 130;

static INTERRUPTED: AtomicBool = AtomicBool::new(false);

/// Installs the handler and returns the flag the first Ctrl-C sets.
pub fn install() -> anyhow::Result<&'static AtomicBool> {
    ctrlc::set_handler(|| {
        if INTERRUPTED.swap(true, Ordering::SeqCst) {
            std::process::exit(INTERRUPTED_EXIT_CODE as i32);
        }
    })
    .context("cannot install the Ctrl-C handler")?;
    Ok(&INTERRUPTED)
}
