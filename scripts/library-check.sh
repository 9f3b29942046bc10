#!/usr/bin/env bash
# The library as a published crate would be: it packages, its documentation builds without a
# warning, its doctests (the crate guide among them) pass, and its examples run at small sizes and
# print what they computed. Any failure fails the run.
set -euo pipefail
cd "$(dirname "$0")/.."

cargo package -p englobe --no-verify --allow-dirty
RUSTDOCFLAGS="-D warnings" cargo doc -p englobe --no-deps
cargo test -p englobe --doc
cargo run -p englobe --example line_of_sight -- 32 6
cargo run -p englobe --example audio_occlusion -- 4
cargo run -p englobe --example lidar_scan -- 64 3
cargo run -p englobe --example moving_instances -- 500 3
