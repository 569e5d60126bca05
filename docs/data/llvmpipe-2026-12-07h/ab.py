#!/usr/bin/env python3
"""ab.py DIR: the partner mask's A/B (ab.sh's files): for every scene, size and phase whose name
starts with "collide", the median over the rounds of each binary's phase time (ms), and H / F."""
import glob, json, os, re, statistics, sys
from collections import defaultdict

d = sys.argv[1] if len(sys.argv) > 1 else os.path.dirname(__file__)
t = defaultdict(list)
for f in sorted(glob.glob(os.path.join(d, "*_[FH]_*.txt"))):
    m = re.match(r"(.+)_([FH])_(\d+)\.txt", os.path.basename(f))
    scene, b = m.group(1), m.group(2)
    for r in json.load(open(f))["records"]:
        for p in r["phases"]:
            if p["phase"].startswith("collide"):
                t[(scene, r["particles"], b)].append(p["ms"])
print("| scene | particles | F ms (each partner as visited) | H ms (partner mask) | H / F |")
print("| --- | ---: | ---: | ---: | ---: |")
for (scene, n) in sorted({(k[0], k[1]) for k in t}):
    f, h = t[(scene, n, "F")], t[(scene, n, "H")]
    if f and h:
        mf, mh = statistics.median(f), statistics.median(h)
        print(f"| {scene} | {n:,} | {mf:.2f} ({len(f)} runs, {min(f):.2f}-{max(f):.2f}) "
              f"| {mh:.2f} ({len(h)} runs, {min(h):.2f}-{max(h):.2f}) | {mh / mf:.2f} |")
