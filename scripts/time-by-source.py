#!/usr/bin/env python3
"""Where a function's time goes, by englobe source file and line: a `perf record -e cpu-clock`
profile (sampled by the kernel's clock, which needs no hardware counter) of one function,
each sample's instruction charged to the innermost frame of its inline chain that lies in
`crates/englobe/src` (an intrinsic's or the standard library's lines are charged to the englobe
line that called them). Unlike callgrind (`scripts/annotate-instructions.py`), this runs the
AVX-512 code and counts time, not instructions; like every timing here, it moves from run to run.

    scripts/time-by-source.py PERF_DATA BINARY FUNCTION [LINES]

PERF_DATA is `perf record`'s output, BINARY the profiled program, FUNCTION the function's full
name as perf shows it; LINES (default 30) the number of source lines listed after the files.
For example, the packet walk inside the Sponza:

    perf record -e cpu-clock -F 10000 -o packets.data target/release/englobe-bench --threads 1 \\
        --reps 150 --build-reps 1 --no-check --quiet --libraries englobe-packet16 \\
        --cells primary-closest --resolution 512 --csv target/packets.csv \\
        sponza-inside=../shared/scenes/meshes/sponza-dabrovic/sponza.obj \\
        --view "sponza-inside=-10.43876,7.37331,0.00149,1,0,0,60"
    scripts/time-by-source.py packets.data target/release/englobe-bench \\
        englobe::accel::wide::dispatch::x86::closest_packet_avx512

Needs `perf` and binutils' `addr2line`.
"""

import collections
import re
import subprocess
import sys

OWN = "crates/englobe/src/"


def main() -> int:
    if len(sys.argv) not in (4, 5):
        print(__doc__.split("\n\n")[1], file=sys.stderr)
        return 2
    data, binary, function = sys.argv[1:4]
    lines = int(sys.argv[4]) if len(sys.argv) == 5 else 30
    annotated = subprocess.run(
        ["perf", "annotate", "-i", data, "--stdio", "--no-source", "--show-nr-samples", "-s", function],
        capture_output=True, text=True, check=True,
    ).stdout
    # Sample counts, not perf's percentages: those are rounded to two decimals per instruction,
    # and a thousand instructions of one or two samples each would add up to more than 100 %.
    counts = []
    for line in annotated.splitlines():
        m = re.match(r"\s+([0-9]+)\s+:\s+([0-9a-f]+):", line)
        if m:
            counts.append((int(m.group(1)), int(m.group(2), 16)))
    total = sum(n for n, _ in counts)
    if total == 0:
        print(f"no samples of {function} in {data}", file=sys.stderr)
        return 1
    samples = [(100.0 * n / total, address) for n, address in counts if n]
    # `addr2line -i -a` prints each address, then its inline chain, innermost frame first.
    chains, current = {}, None
    out = subprocess.run(
        ["addr2line", "-i", "-a", "-e", binary] + [hex(a) for _, a in samples],
        capture_output=True, text=True, check=True,
    ).stdout
    for line in out.splitlines():
        if line.startswith("0x"):
            current = int(line, 16)
            chains[current] = []
        elif line.strip() and current is not None:
            chains[current].append(line.strip())
    by_file, by_line = collections.Counter(), collections.Counter()
    for percent, address in samples:
        own = [f for f in chains.get(address, []) if OWN in f]
        where = own[0].split(OWN, 1)[1].split(" ")[0] if own else "(outside englobe)"
        by_line[where] += percent
        by_file[where.rsplit(":", 1)[0]] += percent
    print(f"per cent of {function}'s samples, by source file:")
    for name, percent in by_file.most_common():
        print(f"{percent:7.2f}  {name}")
    print("\nby source line:")
    for name, percent in by_line.most_common(lines):
        print(f"{percent:7.2f}  {name}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
