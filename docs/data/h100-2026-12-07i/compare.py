#!/usr/bin/env python3
"""compare.py DIR [BASE]: for files DIR/SCENE_B_ROUND.txt (`texflow bench scene ... --json`, B a
capital letter and an optional digit naming a binary, as P4), the median over the rounds of each
binary's collision stage (the phase whose name starts with "collide", ms), per scene and size,
and its ratio to binary BASE's (F)."""
import glob, json, os, re, statistics, sys
from collections import defaultdict

d = sys.argv[1]
base = sys.argv[2] if len(sys.argv) > 2 else "F"
t = defaultdict(list)
for f in sorted(glob.glob(os.path.join(d, "*_*_*.txt"))):
    m = re.match(r"(.+)_([A-Z][0-9]?)_(\d+)\.txt", os.path.basename(f))
    for r in json.load(open(f))["records"]:
        for p in r["phases"]:
            if p["phase"].startswith("collide"):
                t[(m.group(1), r["particles"], m.group(2))].append(p["ms"])
bins = sorted({k[2] for k in t})
print("| scene | particles | " + " | ".join(f"{b} ms (runs, range)" for b in bins)
      + " | " + " | ".join(f"{b} / {base}" for b in bins if b != base) + " |")
print("| --- | ---: |" + " ---: |" * (2 * len(bins) - (base in bins)))
for (scene, n) in sorted({(k[0], k[1]) for k in t}):
    med = {b: statistics.median(t[(scene, n, b)]) for b in bins if t.get((scene, n, b))}
    cells = [f"{med[b]:.2f} ({len(t[(scene, n, b)])}, {min(t[(scene, n, b)]):.2f}-"
             f"{max(t[(scene, n, b)]):.2f})" if b in med else "–" for b in bins]
    ratios = [f"{med[b] / med[base]:.2f}" if b in med and base in med else "–"
              for b in bins if b != base]
    print(f"| {scene} | {n:,} | " + " | ".join(cells) + " | " + " | ".join(ratios) + " |")
