#!/usr/bin/env bash
# Instructions per triangle of each library's build, counted by callgrind: exact and repeatable on
# a shared machine, where build times are not. Each count is the difference between a run of the
# harness with three timed builds and one with a single timed build, divided by the two builds'
# triangles: loading the mesh, the warm-up build and the rays cancel out.
#
#   scripts/build-instructions.sh [LIBRARY,LIBRARY...] -- SCENE... [-- HARNESS OPTIONS]
#
# SCENE is a harness scene (`name=path`, say sponza=../shared/scenes/meshes/sponza-dabrovic/sponza.obj);
# options after a second `--` go to every run (`--englobe-presplit 40`: the pre-split alone).
# LIBRARY defaults to englobe; `embree` needs the harness built with the `embree` feature
# (scripts/bench-anchors.sh installs Embree). One thread.
#
# The binary is ENGLOBE_BENCH (default target/release/englobe-bench), used as it is: to compare
# two revisions, point it at each one's harness in turn (scripts/ab-bench.sh keeps them under
# target/ab-bench/bin/). Valgrind cannot run AVX-512: a harness built with
# `RUSTFLAGS="-C target-cpu=x86-64-v3"` runs under it as it would on an AVX2 processor; Embree
# chooses its AVX2 kernels by itself.
set -euo pipefail
cd "$(dirname "$0")/.."
usage() { sed -n '7,12s/^# \{0,1\}//p' "$0" >&2; exit 2; }
libraries="englobe"
if [[ $# -ge 1 && "$1" != "--" ]]; then
    libraries="$1"
    shift
fi
[[ "${1:-}" == "--" ]] || usage
shift
scenes=()
while [[ $# -ge 1 && "$1" != "--" ]]; do
    scenes+=("$1")
    shift
done
[[ ${#scenes[@]} -ge 1 ]] || usage
[[ "${1:-}" == "--" ]] && shift
extra=("$@")
bench="${ENGLOBE_BENCH:-target/release/englobe-bench}"
command -v valgrind >/dev/null || { echo "valgrind is needed (apt-get install valgrind)" >&2; exit 1; }
[[ -x "$bench" ]] || { echo "$bench: no such binary" >&2; exit 1; }
work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT

# Instructions of one run: `count LIBRARY SCENE BUILDS`.
count() {
    valgrind --tool=callgrind --callgrind-out-file="$work/out" "$bench" --threads 1 --reps 1 --build-reps "$3" \
        --no-check --quiet --libraries "$1" --cells primary-closest --resolution 16 \
        -o "$work/csv" "$2" "${extra[@]}" > /dev/null 2> "$work/log" || { cat "$work/log" >&2; exit 1; }
    sed -n 's/^summary: \([0-9]*\).*/\1/p' "$work/out"
}

printf '%-24s %-10s %12s\n' scene library instructions/triangle
for scene in "${scenes[@]}"; do
    for library in ${libraries//,/ }; do
        one=$(count "$library" "$scene" 1)
        three=$(count "$library" "$scene" 3)
        triangles=$(python3 -c 'import csv, sys; print(next(csv.DictReader(open(sys.argv[1])))["triangles"])' "$work/csv")
        awk -v s="${scene%%=*}" -v l="$library" -v a="$one" -v b="$three" -v n="$triangles" \
            'BEGIN { printf "%-24s %-10s %12.0f\n", s, l, (b - a) / (2 * n) }'
    done
done
