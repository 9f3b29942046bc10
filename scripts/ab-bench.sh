#!/usr/bin/env bash
# Two revisions of englobe timed against each other on single rays, as fairly as a shared machine
# allows: each revision is built several times with its loops placed differently, and the
# binaries are run in turn, round after round, so that neither code placement (which moves a
# single-ray timing by 5 % and more on some processors, with the same instructions: see
# docs/performance.md) nor the machine's other work favours one of them.
#
#   scripts/ab-bench.sh REV_A REV_B [ROUNDS]
#
# REV_A and REV_B are git revisions (a commit, a branch, HEAD~1). Each is checked out under
# target/ab-bench/ and its harness built once per placement: the compiler's own, then with every
# loop aligned to each of ALIGNS bytes (`-C llvm-args=-align-loops=N` on the harness crate, where
# the walks are compiled, being generic). Then ROUNDS rounds (default 5), each running every
# binary once, A and B alternately first: one thread, the cells CELLS, RAYS rays, on SCENES.
#
# Prints, per cell, the median rays per second of each revision over all its runs, and B/A for
# each placement (medians over the rounds) with their median: a change is worth as much as what
# it gains under every placement, not under one. Then the runs paired: B/A of the two binaries of
# one placement run one after the other in the same round, whose median is less moved by the
# machine's load drifting from round to round, and how many of those pairs B won: a change that
# wins about half of them has not been told apart from the noise. The runs' CSVs stay in
# target/ab-bench/runs/; the binaries in target/ab-bench/bin/, by commit and placement, for the
# next comparison.
#
# Each scene's build is compared too, as builds per second (the harness's median of BUILD_REPS
# builds on THREADS threads): to time builds, give BUILD_REPS of 5 or more and THREADS 2, with a
# cheap cell and few RAYS.
#
# Environment (defaults in brackets): ALIGNS ["32 64"], CELLS
# [primary-closest,random-closest,random-any,bounce-closest], LIBRARY [englobe; englobe-packet16
# times the packet walks], RAYS [500000], RESOLUTION [512], REPS [5], THREADS [1], BUILD_REPS [1],
# ENGLOBE_SHARED [../shared], SCENES [the bunny, the ogre and the Sponza seen from inside, as
# harness arguments].
set -euo pipefail
cd "$(dirname "$0")/.."
[[ $# -ge 2 ]] || { sed -n '8,8s/^# \{0,1\}//p' "$0" >&2; exit 2; }
rounds=${3:-5}
aligns=(default ${ALIGNS-32 64})
cells=${CELLS:-primary-closest,random-closest,random-any,bounce-closest}
meshes=${ENGLOBE_SHARED:-../shared}/scenes/meshes
if [[ -n ${SCENES:-} ]]; then
    read -r -a scenes <<< "$SCENES"
else
    scenes=("bunny=$meshes/bunny/stanford-bunny.obj" "ogre=$meshes/ogre/ogre.obj"
        "sponza-inside=$meshes/sponza-dabrovic/sponza.obj"
        --view "sponza-inside=-10.43876,7.37331,0.00149,1,0,0,60")
fi
root=$(pwd)
work=$root/target/ab-bench
mkdir -p "$work/bin"
rm -rf "$work/runs"
mkdir -p "$work/runs"

# Builds revision $2 as side $1 ("A" or "B"), once per placement, unless an earlier run did:
# the binaries are kept under target/ab-bench/bin/, named by commit and placement.
build() {
    local side=$1 sha
    sha=$(git rev-parse --verify "$2^{commit}")
    local src=$work/src-$side
    rm -rf "$src"
    git worktree prune
    for align in "${aligns[@]}"; do
        local bin=$work/bin/$sha-$align
        if [[ ! -x $bin ]]; then
            [[ -d $src ]] || git worktree add --detach --quiet "$src" "$sha"
            local flags=()
            [[ $align == default ]] || flags=(-C "llvm-args=-align-loops=$align")
            echo "building $side ($2, ${sha:0:10}), loops aligned: $align" >&2
            # One target folder for both sides: the dependencies are built once.
            (cd "$src" && CARGO_TARGET_DIR=$work/target cargo rustc --quiet --release -p englobe-bench \
                --bin englobe-bench -- "${flags[@]}")
            cp "$work/target/release/englobe-bench" "$bin.tmp"
            mv "$bin.tmp" "$bin"
        fi
        ln -sf "$bin" "$work/run-$side-$align"
    done
    [[ ! -d $src ]] || git worktree remove --force "$src"
}
build A "$1"
build B "$2"

for round in $(seq 1 "$rounds"); do
    order=(A B)
    ((round % 2 == 0)) && order=(B A)
    for align in "${aligns[@]}"; do
        for side in "${order[@]}"; do
            "$work/run-$side-$align" --threads "${THREADS:-1}" --reps "${REPS:-5}" --build-reps "${BUILD_REPS:-1}" \
                --no-check --quiet \
                --libraries "${LIBRARY:-englobe}" --cells "$cells" --rays "${RAYS:-500000}" --resolution "${RESOLUTION:-512}" \
                --csv "$work/runs/$side-$align-$round.csv" "${scenes[@]}" > /dev/null
        done
    done
    echo "round $round of $rounds done" >&2
done

echo "A: $1 ($(git rev-parse --short "$1")), B: $2 ($(git rev-parse --short "$2")); ${LIBRARY:-englobe}, $rounds rounds, ${THREADS:-1} thread(s)"
python3 - "$work/runs" "${aligns[@]}" <<'EOF'
import csv, pathlib, statistics, sys
from collections import defaultdict

runs, aligns = pathlib.Path(sys.argv[1]), sys.argv[2:]
by_round = {}  # (cell, side, align, round) -> rays per second
for path in sorted(runs.glob("*.csv")):
    side, align, round_ = path.stem.split("-")
    for row in csv.DictReader(path.open()):
        if row["rays"] != "build":
            cell = f'{row["scene"]} {row["rays"]} {row["query"]}'
            by_round[cell, side, align, round_] = float(row["mrays_per_s"])
            # Every row of a scene repeats its build's time; as a rate, so that B/A above 1 is
            # B faster, as for rays.
            if row["build_ms"]:
                by_round[f'{row["scene"]} build (per s)', side, align, round_] = 1000.0 / float(row["build_ms"])
rates = defaultdict(list)  # (cell, side, align) -> rays per second of each round
for (cell, side, align, _), rate in by_round.items():
    rates[cell, side, align].append(rate)
cells = sorted({cell for cell, _, _ in rates})
head = f'{"cell":32} {"A Mrays/s":>10} {"B Mrays/s":>10}' + "".join(f' {"B/A " + a:>11}' for a in aligns)
print(head + f' {"median":>7} {"paired":>7} {"B won":>7}')
for cell in cells:
    every = {s: [r for a in aligns for r in rates[cell, s, a]] for s in "AB"}
    ratios = [statistics.median(rates[cell, "B", a]) / statistics.median(rates[cell, "A", a]) for a in aligns]
    pairs = [
        rate / by_round[cell, "A", a, r]
        for (c, s, a, r), rate in by_round.items()
        if (c, s) == (cell, "B") and (cell, "A", a, r) in by_round
    ]
    line = f"{cell:32} {statistics.median(every['A']):10.3f} {statistics.median(every['B']):10.3f}"
    won = f"{sum(p > 1 for p in pairs)}/{len(pairs)}"
    print(line + "".join(f" {r:11.3f}" for r in ratios) + f" {statistics.median(ratios):7.3f}"
          + f" {statistics.median(pairs):7.3f} {won:>7}")
EOF
