#!/usr/bin/env python3
"""How often each machine instruction of a function ran, per ray: a callgrind profile recorded with
`--dump-instr=yes` joined with the function's disassembly (objdump, with source lines where the
binary has line tables).

    scripts/annotate-instructions.py PROFILE FUNCTION RAYS [--summary]

PROFILE is callgrind's output file; FUNCTION a substring of the function's name as callgrind gives
it (for a stripped library such as Debian's Embree, its address: `0x0000000001960660`); RAYS the
number of queries the profiled run made (the harness traces its rays once to warm up, then once
per `--reps`). Every function whose name contains FUNCTION is counted, all copies together.

Prints one line per instruction that ran: executions per ray, address, instruction, source line;
then the instructions per ray by source file, and in all. `--summary` prints only the totals.
Where `docs/performance.md` takes its per-instruction figures from, for example:

    valgrind --tool=callgrind --dump-instr=yes --callgrind-out-file=any.out \\
        target/release/englobe-bench --threads 1 --reps 3 --build-reps 1 --no-check --quiet \\
        --libraries englobe --cells random-any --rays 100000 --resolution 128 \\
        sponza-inside=../shared/scenes/meshes/sponza-dabrovic/sponza.obj \\
        --view "sponza-inside=-10.43876,7.37331,0.00149,1,0,0,60"
    scripts/annotate-instructions.py any.out x86::ray_query_avx2 400000

(with the harness built for `-C target-cpu=x86-64-v3`: valgrind cannot run AVX-512).

RAYS must count every query the profiled run made to the function. Before measuring, the harness
traces its primary rays once with englobe's closest-hit query, to start the bounce rays from their
hits: a closest-hit profile counts those `resolution * resolution` queries too (16 384 more at
`--resolution 128`, 4 % of 400 000). Profile closest-hit cells with a small `--resolution` (8),
or add them to RAYS.
"""

import collections
import re
import subprocess
import sys


def position(token, last):
    """A callgrind position: absolute, relative to the last one (`+n`, `-n`), or the same (`*`)."""
    if token == "*":
        return last
    if token[0] in "+-":
        return last + int(token, 0)
    return int(token, 0)


def counts(profile, pattern):
    """Executions of each instruction of the functions whose name contains `pattern`, and the
    object file they belong to."""
    names, objects = {}, {}
    function = obj = None
    found_in = set()
    executed = collections.Counter()
    address = line = 0
    skip_next = False
    with open(profile) as f:
        for text in f:
            text = text.rstrip("\n")
            if not text:
                continue
            m = re.match(r"^(c?fn|c?ob)=\((\d+)\)(?: (.*))?$", text)
            if m:
                kind, index, name = m.groups()
                table = names if kind.endswith("fn") else objects
                if name:
                    table[index] = name
                if kind == "fn":
                    function = names.get(index, index)
                elif kind == "ob":
                    obj = objects.get(index, index)
                continue
            if text.startswith("calls="):
                skip_next = True  # the next line is the call's inclusive cost, not an instruction's
                continue
            if text[0].isdigit() or text[0] in "+-*":
                fields = text.split()
                address, line = position(fields[0], address), position(fields[1], line)
                if skip_next:
                    skip_next = False
                    continue
                if function and pattern in function and len(fields) > 2:
                    executed[address] += int(fields[2])
                    found_in.add(obj)
    return executed, found_in


def main():
    args = [a for a in sys.argv[1:] if a != "--summary"]
    if len(args) != 3:
        sys.exit(__doc__)
    profile, pattern, rays = args[0], args[1], float(args[2])
    executed, objects = counts(profile, pattern)
    if not executed:
        sys.exit(f"{profile}: no instruction of a function matching `{pattern}` ran")
    if len(objects) != 1:
        sys.exit(f"`{pattern}` matches functions in several objects: {sorted(objects)}")
    obj = objects.pop()
    start, stop = min(executed), max(executed) + 16
    listing = subprocess.run(
        ["objdump", "-d", "-l", "--no-show-raw-insn", f"--start-address={start}", f"--stop-address={stop}", obj],
        check=True, capture_output=True, text=True).stdout
    by_file = collections.Counter()
    source = "(no line table)"
    seen = 0
    for text in listing.splitlines():
        if text.startswith("/") and ":" in text and "file format" not in text:
            source = text.strip().rsplit("/", 1)[-1]
            continue
        m = re.match(r"^\s+([0-9a-f]+):\s+(.*)$", text)
        if not m or int(m.group(1), 16) not in executed:
            continue
        address = int(m.group(1), 16)
        per_ray = executed[address] / rays
        seen += executed[address]
        by_file[source.split(":")[0]] += per_ray
        if "--summary" not in sys.argv:
            print(f"{per_ray:8.3f}  {address:x}  {m.group(2)[:56]:56}  {source}")
    print("\ninstructions per ray, by source file:")
    for name, n in by_file.most_common():
        print(f"{n:9.1f}  {name}")
    print(f"{sum(executed.values()) / rays:9.1f}  in all ({obj})")
    if seen != sum(executed.values()):
        print(f"({(sum(executed.values()) - seen) / rays:.1f} per ray at addresses objdump did not list)")


if __name__ == "__main__":
    main()
