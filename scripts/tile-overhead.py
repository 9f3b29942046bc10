#!/usr/bin/env python3
"""Measures what cutting a render into tiles costs, on one machine.

    scripts/tile-overhead.py SCENE --tiles 8 [--balance area|cost] [--reps 3] [--binary target/release/englobe]
                             [-- RENDER OPTIONS]

Each repetition renders the scene once as one process, then as N tile processes one after the
other (what N array tasks cost in total), all on one thread, in alternating order. It prints the
median wall times, the overhead of tiling (the N processes' total against the one process; each
tile process loads the scene and builds its structure again), and the balance of the cut: the
longest tile against the mean, in render time and in wall time (what the slowest array task costs
the whole job when every tile has a slot of its own).
"""
import argparse
import re
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path


def run(cmd):
    start = time.perf_counter()
    out = subprocess.run(cmd, check=True, capture_output=True, text=True).stdout
    wall = time.perf_counter() - start
    seconds = float(re.search(r", ([0-9.]+) s on", out).group(1))
    return wall, seconds


def main():
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("scene")
    p.add_argument("--tiles", type=int, default=8)
    p.add_argument("--reps", type=int, default=3)
    p.add_argument("--balance", default="area", choices=["area", "cost"])
    p.add_argument("--binary", default="target/release/englobe")
    argv = sys.argv[1:]
    render = argv[argv.index("--") + 1:] if "--" in argv else []
    a = p.parse_args(argv[:argv.index("--")] if "--" in argv else argv)
    a.render = render
    base = [a.binary, "render", a.scene, "--threads", "1", *a.render]
    one_walls, tile_walls, balances, wall_balances = [], [], [], []
    with tempfile.TemporaryDirectory() as d:
        for rep in range(a.reps):
            def whole():
                one_walls.append(run(base + ["-o", str(Path(d) / "one.png")])[0])

            def tiles():
                walls, renders = [], []
                for k in range(a.tiles):
                    tile = ["--tile", f"{k}/{a.tiles}", "--balance", a.balance]
                    w, s = run(base + tile + ["-o", str(Path(d) / f"t{k}.exr")])
                    walls.append(w)
                    renders.append(s)
                tile_walls.append(sum(walls))
                balances.append(max(renders) / statistics.mean(renders))
                wall_balances.append(max(walls) / statistics.mean(walls))

            for step in ([whole, tiles] if rep % 2 == 0 else [tiles, whole]):
                step()
    one, tiled = statistics.median(one_walls), statistics.median(tile_walls)
    options = " ".join(a.render) or "(the scene's)"
    print(f"scene {a.scene}, options {options}, {a.tiles} tiles cut by {a.balance}, "
          f"{a.reps} repetitions, one thread, medians")
    print(f"one process:        {one:8.3f} s")
    print(f"{a.tiles} tile processes: {tiled:8.3f} s in all ({100 * (tiled / one - 1):+.1f} %)")
    print(f"longest tile / mean tile: {statistics.median(balances):.2f} in render time, "
          f"{statistics.median(wall_balances):.2f} in wall time")


if __name__ == "__main__":
    sys.exit(main())
