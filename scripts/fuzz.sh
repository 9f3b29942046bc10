#!/usr/bin/env bash
# Coverage-guided fuzzing of the scene parsers (TOML, pbrt), each mesh loader, the MTL reader, the
# texture and environment map decoders and the tile reader with cargo fuzz
# (libFuzzer).
#
#   scripts/fuzz.sh [SECONDS_PER_TARGET] [TARGET...]
#
# Seeds each target's corpus with the project's scenes and the shared meshes, then fuzzes it for
# the given time (default 60 s). Works on stable Rust: no sanitizer (Rust code is memory-safe;
# what is hunted is panics, aborts, hangs and huge allocations, which libFuzzer reports as
# crashes, timeouts and out-of-memory). Crashing inputs land in fuzz/artifacts/TARGET/.
# Needs `cargo install cargo-fuzz`.
set -euo pipefail
cd "$(dirname "$0")/.."
seconds=${1:-60}
shift || true
targets=("$@")
[ ${#targets[@]} -gt 0 ] || targets=(scene_toml pbrt_scene mesh_obj mesh_ply mesh_gltf environment_map tile_exr mtl_text texture_image)
shared=${ENGLOBE_SHARED:-../shared}

seed() {
    local target=$1 dir=fuzz/corpus/$1
    mkdir -p "$dir"
    case $target in
        scene_toml) find scenes -name '*.toml' -exec cp {} "$dir/" \; ;;
        pbrt_scene) find "$shared/scenes" -name '*.pbrt' -size -2M -exec cp {} "$dir/" \; ;;
        mesh_obj) find "$shared/scenes/meshes" -name '*.obj' -size -200k -exec cp {} "$dir/" \; ;;
        mesh_ply) find "$shared/scenes/meshes" -name '*.ply' -size -2M -exec cp {} "$dir/" \; ;;
        mesh_gltf) find "$shared/scenes/meshes" \( -name '*.gltf' -o -name '*.glb' \) -size -2M -exec cp {} "$dir/" \; ;;
        mtl_text) find "$shared/scenes/meshes" -name '*.mtl' -size -200k -exec cp {} "$dir/" \; ;;
        texture_image) find "$shared/scenes/meshes" \( -name '*.png' -o -name '*.jpg' \) -size -200k -exec cp {} "$dir/" \; ;;
        environment_map)
            # The shared maps are large; small ones in both formats seed the corpus instead.
            cargo run -q -- render --width 16 --height 8 --spp 1 -o "$dir/small.exr" -q
            cargo run -q -- render --width 16 --height 8 --spp 1 --half -o "$dir/half.exr" -q
            printf '#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y 1 +X 2\n\x80\x40\x20\x81\0\0\0\0' > "$dir/tiny.hdr"
            ;;
        tile_exr)
            for t in 0/1 1/3; do
                cargo run -q -- render --width 16 --height 9 --spp 1 --tile "$t" -o "$dir/tile-${t%/*}.exr" -q
            done
            ;;
    esac
}

for target in "${targets[@]}"; do
    seed "$target"
    echo "== $target: ${seconds} s"
    (cd fuzz && cargo fuzz run --sanitizer none -O "$target" "corpus/$target" -- \
        -max_total_time="$seconds" -rss_limit_mb=4096 -timeout=10 -max_len=1048576 -print_final_stats=1)
done
