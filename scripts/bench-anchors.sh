#!/usr/bin/env bash
# The anchor benchmark of docs/performance.md: englobe against Intel Embree (single rays and
# 16-ray packets), obvhs and bvh on the same primary, random and bounce rays, on the Stanford
# bunny, the ogre, the Sponza atrium (framed from outside, and seen from inside with the primary
# rays of a camera in the atrium, 96 % of them hitting) and a generated scene of 8.7 million
# triangles (the bunny tiled 5x5x5), on 2 threads, median of 5 runs, every library checked
# against brute force. Each library's build is reported in milliseconds and in bytes per
# triangle (the growth of the process's resident memory across its first build).
#
#   scripts/bench-anchors.sh [CSV] [extra englobe-bench options...]
#
# Installs Debian's libembree-dev (Embree 3) with apt-get if it is missing, builds the harness
# in release mode with the `embree` feature and runs it. The CSV (default
# target/bench-anchors.csv) has one row per measurement; its path is the last line printed.
# Only ratios within one run mean anything: the machine's other work moves every figure.
set -euo pipefail
cd "$(dirname "$0")/.."
csv=${1:-target/bench-anchors.csv}
shift || true
shared=${ENGLOBE_SHARED:-../shared}
meshes=$shared/scenes/meshes

if ! dpkg -s libembree-dev >/dev/null 2>&1; then
    echo "installing libembree-dev (Embree 3)" >&2
    sudo=""
    [ "$(id -u)" -eq 0 ] || sudo=sudo
    $sudo apt-get update >&2
    $sudo apt-get install -y libembree-dev >&2
fi

cargo build --release -p englobe-bench --features embree >&2
mkdir -p "$(dirname "$csv")"
exec target/release/englobe-bench \
    --threads 2 --reps 5 --csv "$csv" "$@" \
    "bunny=$meshes/bunny/stanford-bunny.obj" \
    "ogre=$meshes/ogre/ogre.obj" \
    "sponza=$meshes/sponza-dabrovic/sponza.obj" \
    "sponza-inside=$meshes/sponza-dabrovic/sponza.obj" \
    --view "sponza-inside=-10.43876,7.37331,0.00149,1,0,0,60" \
    "bunny-5x5x5=$meshes/bunny/stanford-bunny.obj@5x5x5"
