#!/usr/bin/env python3
"""The table of docs/performance.md ("The table") from the CSV of a `scripts/bench-anchors.sh` run.

    scripts/anchor-table.py CSV [LOG]

CSV is the file the run wrote (`target/anchorsNN.csv`); LOG, if given, the run's printed output,
from which the fraction of each scene's primary rays that hit is taken (the CSV does not hold it).
Prints the Markdown table, one row per library and scene: build time, the growth of resident
memory in bytes per triangle, million rays per second per cell and, in brackets, the ratio to
Embree's `rtcIntersect1`/`rtcOccluded1` in the same run; englobe's single-ray row in bold. Then a
line per scene with englobe's packets against Embree's `rtcIntersect16` on primary rays, and
englobe's build time against Embree's.
"""

import csv
import re
import sys

CELLS = [("primary", "closest"), ("random", "closest"), ("random", "any"), ("bounce", "closest")]
SCENES = {
    "bunny": "bunny",
    "ogre": "ogre",
    "sponza": "Sponza from outside",
    "sponza-inside": "Sponza from inside",
    "bunny-5x5x5": "bunny tiled 5x5x5",
}


def grouped(n):
    """An integer with its thousands apart, as the documents write them: 8 681 375."""
    return f"{n:,}".replace(",", " ")


def library_name(library, structure):
    embree = re.match(r"Embree (\d+\.\d+)", structure)
    if library == "embree" and embree:
        return f"Embree {embree.group(1)} `rtcIntersect1`"
    if library == "embree-packet16" and embree:
        return f"Embree {embree.group(1)} `rtcIntersect16`"
    isa = re.search(r"\((\w+)\)", structure)
    if library == "englobe":
        if not isa:
            return "**englobe**"
        return f"**englobe** `TriangleBvh` ({isa.group(1).upper().replace('AVX512', 'AVX-512')})"
    if library == "englobe-packet16":
        return "englobe, 16-ray packets"
    if library == "obvhs":
        return "obvhs (`CwBvh`)"
    return library


def hit_fractions(log):
    """Each scene's primary rays that hit, in percent, from the run's output."""
    found = {}
    for line in open(log, encoding="utf-8", errors="replace"):
        m = re.match(r"([\w.-]+): \d+ triangles; rays hitting: primary ([\d.]+) %", line)
        if m:
            found[m.group(1)] = m.group(2)
    return found


def main():
    if len(sys.argv) not in (2, 3):
        sys.exit(__doc__)
    try:
        rows = list(csv.DictReader(open(sys.argv[1], encoding="utf-8")))
        hits = hit_fractions(sys.argv[2]) if len(sys.argv) == 3 else {}
    except OSError as e:
        sys.exit(f"anchor-table: {e}")
    needed = {"scene", "library", "rays", "query", "mrays_per_s", "ratio_to_embree", "build_ms",
              "build_bytes_per_triangle", "triangles", "structure"}
    if not rows or not needed <= set(rows[0]):
        sys.exit(f"anchor-table: {sys.argv[1]} is not a CSV of scripts/bench-anchors.sh "
                 f"(it needs the columns {', '.join(sorted(needed))})")
    scenes = list(dict.fromkeys(r["scene"] for r in rows))
    libraries = list(dict.fromkeys(r["library"] for r in rows))
    cell = {(r["scene"], r["library"], r["rays"], r["query"]): r for r in rows}
    print("| scene (triangles; primary rays hitting) | library | build ms | B/tri "
          "| primary, closest | random, closest | random, any-hit | bounce, closest |")
    print("|---|---|---|---|---|---|---|---|")
    for scene in scenes:
        first = True
        for library in libraries:
            mine = [cell.get((scene, library) + c) for c in CELLS]
            if not any(mine):
                continue
            some = next(r for r in mine if r)
            label = ""
            if first:
                hit = f"; {hits[scene]} %" if scene in hits else ""
                label = f"{SCENES.get(scene, scene)} ({grouped(int(some['triangles']))}{hit})"
                first = False
            bold = "**" if library == "englobe" else ""
            cells = []
            for r in mine:
                if r is None:
                    cells.append("")
                    continue
                speed, ratio = float(r["mrays_per_s"]), float(r["ratio_to_embree"])
                cells.append(f"{bold}{speed:.2f} ({ratio:.2f}){bold}")
            name = library_name(library, some["structure"])
            build, grown = float(some["build_ms"]), float(some["build_bytes_per_triangle"])
            print(f"| {label} | {name} | {build:.1f} | {grown:.0f} | " + " | ".join(cells) + " |")
    print()
    for scene in scenes:
        name = SCENES.get(scene, scene)
        packets = cell.get((scene, "englobe-packet16", "primary", "closest"))
        theirs = cell.get((scene, "embree-packet16", "primary", "closest"))
        ours = cell.get((scene, "englobe", "primary", "closest"))
        embree = cell.get((scene, "embree", "primary", "closest"))
        parts = []
        if packets and theirs:
            ratio = float(packets["mrays_per_s"]) / float(theirs["mrays_per_s"])
            parts.append(f"packets {ratio:.2f} of `rtcIntersect16`")
        if ours and embree:
            ratio = float(ours["build_ms"]) / float(embree["build_ms"])
            parts.append(f"build {ratio:.2f}x Embree's time")
        print(f"{name}: " + ", ".join(parts))


if __name__ == "__main__":
    main()
