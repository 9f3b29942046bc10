#!/usr/bin/env bash
# Instructions per ray of each harness cell, per library, counted by callgrind: exact and
# repeatable on a shared machine, where timings are not. Each count is the difference between a
# run of the harness with three timed passes over the rays and one with a single pass, divided by
# the two passes' rays: loading the mesh, the build, the warm-up and the generation of the rays
# cancel out, and what is left is the library's query and the harness's loop around it.
#
#   scripts/ray-instructions.sh MESH [LIBRARY,LIBRARY...] [-- HARNESS OPTIONS]
#
# MESH is a harness scene (`name=path`, say bunny=../shared/scenes/meshes/bunny/stanford-bunny.obj);
# options after `--` go to every run (`--view name=...` for a camera inside). LIBRARY defaults to
# englobe; `embree` needs the harness built with the `embree` feature (scripts/bench-anchors.sh
# installs Embree). One thread, 100 000 random and bounce rays, 128 x 128 primary rays.
#
# The binary is ENGLOBE_BENCH (default target/release/englobe-bench), used as it is: build it with
# `RUSTFLAGS="-C target-cpu=x86-64-v3" cargo build --release -p englobe-bench --features embree`
# first. Valgrind cannot run AVX-512, so both englobe and Embree run their AVX2 kernels.
set -euo pipefail
cd "$(dirname "$0")/.."
[[ $# -ge 1 ]] || { sed -n '8,13s/^# \{0,1\}//p' "$0" >&2; exit 2; }
mesh="$1"
shift
libraries="englobe"
if [[ $# -ge 1 && "$1" != "--" ]]; then
    libraries="$1"
    shift
fi
[[ "${1:-}" == "--" ]] && shift
extra=("$@")
bench="${ENGLOBE_BENCH:-target/release/englobe-bench}"
command -v valgrind >/dev/null || { echo "valgrind is needed (apt-get install valgrind)" >&2; exit 1; }
[[ -x "$bench" ]] || { echo "$bench: no such binary (see the comment at the top of $0)" >&2; exit 1; }
rays=100000
resolution=128
work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT

# Instructions of one run: `count LIBRARY CELL REPS`.
count() {
    valgrind --tool=callgrind --callgrind-out-file="$work/out" "$bench" --threads 1 --reps "$3" --build-reps 1 \
        --no-check --quiet --libraries "$1" --cells "$2" --rays "$rays" --resolution "$resolution" \
        -o "$work/csv" "$mesh" "${extra[@]}" > /dev/null 2> "$work/log" || { cat "$work/log" >&2; exit 1; }
    sed -n 's/^summary: \([0-9]*\).*/\1/p' "$work/out"
}

printf '%-10s %-16s %12s\n' library cell instructions/ray
for library in ${libraries//,/ }; do
    for cell in primary-closest random-closest random-any bounce-closest; do
        n=$rays
        [[ $cell == primary-* ]] && n=$((resolution * resolution))
        one=$(count "$library" "$cell" 1)
        three=$(count "$library" "$cell" 3)
        awk -v l="$library" -v c="$cell" -v a="$one" -v b="$three" -v n="$n" \
            'BEGIN { printf "%-10s %-16s %12.1f\n", l, c, (b - a) / (2 * n) }'
    done
done
