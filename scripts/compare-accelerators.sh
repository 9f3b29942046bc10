#!/usr/bin/env bash
# Every structure on one ruler: `englobe compare` on the seed's four scenes, the bunny, the Sponza,
# the teapot in a stadium and the uniform triangle soup, as in docs/accelerators.md.
#
#   scripts/compare-accelerators.sh [OUT_DIR]
#
# Writes OUT_DIR/<scene>.txt (the tables), OUT_DIR/<scene>.json and OUT_DIR/<scene>.svg (rays per
# second and exact tests per ray of every structure). OUT_DIR defaults to target/compare.
set -euo pipefail
cd "$(dirname "$0")/.."
out="${1:-target/compare}"
mkdir -p "$out"
cargo build --release --quiet
for scene in seed/test1 seed/test2 seed/test3 seed/test4 bunny sponza teapot-stadium uniform-triangles; do
    name="$(basename "$scene")"
    echo "== $scene" >&2
    ./target/release/englobe compare "scenes/$scene.toml" --quiet \
        --json "$out/$name.json" --plot "$out/$name.svg" | tee "$out/$name.txt"
done
echo "$out"
