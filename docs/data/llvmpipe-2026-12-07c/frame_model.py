#!/usr/bin/env python3
"""The render phases of `bench scene` JSON outputs (bs_NAME.txt in a folder) predicted two ways
from the same run: by the state-sized probe's points constant (the model before the frame's
constants: draws × fixed + bytes + fetches + points × per point) and by the record's own
`predicted_ms` (the frame's constants: points and fragments at the rates measured into the
frame). Prints predicted / measured for both, and how many are within ±25 %.

    python3 frame_model.py FOLDER
"""
import glob
import json
import os
import statistics
import sys

folder = sys.argv[1] if len(sys.argv) > 1 else "."
old, new = [], []
print("| scene | size | render ms | state probe: predicted / ms | frame probes: predicted / ms |")
print("|---|---:|---:|---:|---:|")
for f in sorted(glob.glob(os.path.join(folder, "bs_*.txt"))):
    scene = os.path.basename(f)[3:-4]
    for r in json.load(open(f))["records"]:
        c = r["constants"]
        for p in r["phases"]:
            d = p.get("drawn")
            if not d or d.get("fragments") is None:
                continue
            s = d["stats"]
            o = (
                s["draws"] * c["fixed_ms"]
                + s["bytes_written"] / 1e6 * c["ms_per_mb_written"]
                + s["fetches"] / 1e6 * c["ms_per_m_fetches"]
                + s["points"] / 1e6 * c["ms_per_m_points"]
            )
            old.append(o / p["ms"])
            new.append(p["predicted_ms"] / p["ms"])
            print(f"| {scene} | {r['size']}² | {p['ms']:.3f} | {old[-1]:.2f} | {new[-1]:.2f} |")
for name, v in (("state probe", old), ("frame probes", new)):
    n = sum(1 for x in v if 0.75 <= x <= 1.25)
    print(f"\n{name}: {n} of {len(v)} within ±25 %, median {statistics.median(v):.2f}")
