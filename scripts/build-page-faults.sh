#!/usr/bin/env bash
# Page faults per build of each library, counted by `perf stat` (a software event: it needs no
# hardware counters). Each count is the difference between a run of the harness with 21
# builds and one with a single build, divided by 20: loading the mesh and the first build's
# faults cancel out, and what is left is what a build in a running program pays for the fresh
# memory it writes.
#
#   scripts/build-page-faults.sh MESH... [-- LIBRARY,LIBRARY...]
#
# MESH is a harness scene (`name=path`); LIBRARY defaults to englobe,embree (`embree` needs the
# harness built with the `embree` feature). Two threads. The binary is ENGLOBE_BENCH (default
# target/release/englobe-bench), used as it is.
set -euo pipefail
cd "$(dirname "$0")/.."
[[ $# -ge 1 ]] || { sed -n '8,13s/^# \{0,1\}//p' "$0" >&2; exit 2; }
meshes=()
while [[ $# -ge 1 && "$1" != "--" ]]; do
    meshes+=("$1")
    shift
done
[[ "${1:-}" == "--" ]] && shift
libraries="${1:-englobe,embree}"
bench="${ENGLOBE_BENCH:-target/release/englobe-bench}"
command -v perf > /dev/null || { echo "perf is needed (Debian: linux-perf)" >&2; exit 1; }
scratch="$(mktemp -d)"
trap 'rm -rf "$scratch"' EXIT

faults() {
    perf stat -x, -e page-faults -o "$scratch/stat" "$bench" --threads 2 --reps 1 --build-reps "$3" \
        --no-check --quiet --libraries "$2" --cells primary-closest --rays 100 --resolution 16 \
        -o "$scratch/out.csv" "$1" > /dev/null
    awk -F, '/page-faults/ { print $1 }' "$scratch/stat"
}

echo "mesh,library,page_faults_per_build"
for mesh in "${meshes[@]}"; do
    IFS=, read -ra libs <<< "$libraries"
    for lib in "${libs[@]}"; do
        one="$(faults "$mesh" "$lib" 1)"
        many="$(faults "$mesh" "$lib" 21)"
        echo "${mesh%%=*},$lib,$(((many - one) / 20))"
    done
done
