#!/usr/bin/env bash
# Render time of each structure, alternated: the structures take turns, round after round, so
# that a busy machine slows them alike, and the report gives each one's best and median time and
# the ratios of the first structure's to each other's. A render at 320x240 lasts a few
# hundredths of a second, too short to time on a shared machine: `--scale` makes it longer.
#
#   scripts/render-speed.sh [SCENE] [SCALE] [ROUNDS] [ACCEL,ACCEL...]
#
# Defaults: scenes/bunny.toml, --scale 4, 7 rounds, bvh-sah,bvh-wide; one thread (the renders of
# a round run back to back, and two threads on two shared cores time the neighbours more than the
# render). The time is the render's own (`render ... s` in `englobe render`'s report: loading,
# building and writing the image are left out). ENGLOBE=path times another binary.
set -euo pipefail
cd "$(dirname "$0")/.."
scene="${1:-scenes/bunny.toml}"
scale="${2:-4}"
rounds="${3:-7}"
accels="${4:-bvh-sah,bvh-wide}"
bin="${ENGLOBE:-./target/release/englobe}"
[[ -n "${ENGLOBE:-}" ]] || cargo build --release --quiet
work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT
for round in $(seq "$rounds"); do
    for accel in ${accels//,/ }; do
        line="$("$bin" render "$scene" --accel "$accel" --threads 1 --scale "$scale" -o "$work/$accel.png" 2>&1)"
        seconds="$(sed -n 's/.*render \([0-9.]*\) s).*/\1/p' <<< "$line")"
        [[ -n "$seconds" ]] || { echo "$line" >&2; exit 1; }
        echo "$seconds" >> "$work/$accel.times"
    done
done
first="${accels%%,*}"
for accel in ${accels//,/ }; do
    cmp -s "$work/$first.png" "$work/$accel.png" || { echo "$accel drew another image than $first" >&2; exit 1; }
done
echo "$scene at --scale $scale, $rounds rounds, one thread; render seconds (best, median), $first / this"
for accel in ${accels//,/ }; do
    sort -n "$work/$accel.times" | awk -v a="$accel" -v f="$(sort -n "$work/$first.times" | paste -sd' ')" '
        { t[NR] = $1 }
        END {
            n = split(f, ft, " ");
            best = t[1]; median = t[int((NR + 1) / 2)];
            fbest = ft[1]; fmedian = ft[int((n + 1) / 2)];
            printf "%-12s best %6.3f s  median %6.3f s   %.2f (best)  %.2f (median)\n", a, best, median, fbest / best, fmedian / median
        }'
done
