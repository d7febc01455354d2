#!/usr/bin/env python3
"""Two or more lodrefine builds on one dev tile, run alternately building by building (the
machine's drift then falls on all of them alike), each building's best of N runs: the median and
max per timed stage, the process wall, and how many outputs equal the first build's.

    scripts/ab_tile.py BIN1,BIN2[,...] TILE_DIR [RUNS=3] [-- extra refine args for every build]

A build may be a wrapper script adding options (`exec build/lodrefine "$@" --ransac 0`).
"""
import filecmp
import json
import os
import statistics
import subprocess
import sys
import tempfile
import time

args = sys.argv[1:]
extra = args[args.index("--") + 1:] if "--" in args else []
args = args[:args.index("--")] if "--" in args else args
bins, tile = args[0].split(","), args[1]
runs = int(args[2]) if len(args) > 2 else 3
ids = sorted(f[:-4] for f in os.listdir(os.path.join(tile, "models")) if f.endswith(".obj"))
out = tempfile.mkdtemp(prefix="ab_tile.")
best = [{} for _ in bins]
for _ in range(runs):
    for i in ids:
        for b, binary in enumerate(bins):
            d = os.path.join(out, str(b))
            os.makedirs(d, exist_ok=True)
            t = time.time()
            subprocess.run([binary, "refine", "--model", f"{tile}/models/{i}.obj", "--cloud", f"{tile}/clouds/{i}.ply",
                            "--out", f"{d}/{i}.obj", "--report", f"{d}/{i}.json"] + extra,
                           stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, check=False)
            seconds = json.load(open(f"{d}/{i}.json"))["seconds"]
            seconds["wall"] = time.time() - t
            kept = best[b].setdefault(i, {})
            for k, v in seconds.items():
                kept[k] = min(kept.get(k, float("inf")), v)
for b, binary in enumerate(bins):
    same = sum(filecmp.cmp(f"{out}/0/{i}.obj", f"{out}/{b}/{i}.obj", shallow=False) for i in ids)
    cells = []
    for k in ["planes", "matching", "selection", "judge", "total", "wall"]:
        v = [best[b][i].get(k, 0.0) for i in ids]
        cells.append(f"{k} {statistics.median(v):.3f}/{max(v):.3f}")
    print(f"{binary}: " + "  ".join(cells) + f"  (median/max s; outputs equal to the first build's: {same}/{len(ids)})")
