#!/usr/bin/env bash
# Instructions executed by a render's pixels, per structure, counted by callgrind: exact and
# repeatable on a shared machine, where timings are not. Loading the scene and building the
# structure are left out (only `Renderer::pixel`, `Renderer::tile_in_packets` for primary rays
# traced in packets, and what they call are counted).
#
#   scripts/render-instructions.sh [SCENE] [ACCEL,ACCEL...] [-- RENDER OPTIONS]
#
# Defaults: scenes/bunny.toml, bvh-sah,bvh-wide. Renders on one thread with the release binary
# (valgrind runs the AVX2 kernels: it cannot run AVX-512), checks that every structure wrote the
# same image, and prints each count and its ratio to the first structure's.
set -euo pipefail
cd "$(dirname "$0")/.."
scene="${1:-scenes/bunny.toml}"
accels="${2:-bvh-sah,bvh-wide}"
shift $(( $# >= 2 ? 2 : $# ))
[[ "${1:-}" == "--" ]] && shift
command -v valgrind >/dev/null || { echo "valgrind is needed (apt-get install valgrind)" >&2; exit 1; }
cargo build --release --quiet
work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT
first=""
first_png=""
for accel in ${accels//,/ }; do
    valgrind --tool=callgrind --toggle-collect='*Renderer::pixel*' --toggle-collect='*::tile_in_packets*' \
        --callgrind-out-file="$work/$accel.out" \
        ./target/release/englobe render "$scene" --threads 1 --accel "$accel" --quiet -o "$work/$accel.png" "$@" \
        2> "$work/$accel.log"
    count="$(sed -n 's/.*Collected : \([0-9]*\).*/\1/p' "$work/$accel.log")"
    [[ -n "$count" ]] || { cat "$work/$accel.log" >&2; exit 1; }
    if [[ -z "$first" ]]; then
        first="$count"
        first_png="$work/$accel.png"
    elif ! cmp -s "$first_png" "$work/$accel.png"; then
        echo "$accel drew another image than ${accels%%,*}" >&2
        exit 1
    fi
    awk -v a="$accel" -v n="$count" -v f="$first" -v b="${accels%%,*}" \
        'BEGIN { printf "%-16s %10.1f M instructions   %s / this: %.2f\n", a, n / 1e6, b, f / n }'
done
