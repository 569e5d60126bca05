#!/usr/bin/env python3
"""Summarises `texflow bench scene NAME --json` outputs (bs_NAME.txt in a folder): every phase's
ratio to its floor, the phases under 0.95 and over 1.5 (with the largest bound measured beside the
floor, and the phase over it), and the cost model's predicted / measured per phase, and by
the kind of phase (the words before its first colon or space).

    python3 summarise.py FOLDER
"""
import glob
import json
import os
import statistics
import sys

folder = sys.argv[1] if len(sys.argv) > 1 else "."
rows = []
for f in sorted(glob.glob(os.path.join(folder, "bs_*.txt"))):
    for r in json.load(open(f))["records"]:
        scene = os.path.basename(f)[3:-4]
        side = int(round(r["particles"] ** 0.5))
        for p in r["phases"]:
            bounds = [b["ms"] for b in p.get("bounds") or [] if b.get("ms") is not None]
            rows.append(
                dict(
                    kind=p["phase"].split(" ")[0].split(":")[0],
                    scene=scene,
                    size=f"{side}²",
                    phase=p["phase"],
                    ms=p["ms"],
                    ratio=p.get("ratio"),
                    bound=max(bounds, default=None),
                    predicted=p.get("predicted_ms"),
                )
            )
rated = [x for x in rows if x["ratio"] is not None]
low = [x for x in rated if x["ratio"] < 0.95]
high = [x for x in rated if x["ratio"] > 1.5]
print(f"{len(rows)} phases, {len(rated)} with a floor; under 0.95: {len(low)}; over 1.5: {len(high)}")
print("\n| scene | size | phase | ms | ratio to its floor |\n|---|---|---|---:|---:|")
for x in low:
    print(f"| {x['scene']} | {x['size']} | {x['phase'][:60]} | {x['ms']:.4f} | {x['ratio']:.2f} |")
within = [x for x in high if x["bound"] and x["ms"] / x["bound"] <= 1.5]
print(f"\nover 1.5 and within 1.5x of the largest bound measured: {len(within)} of {len(high)}")
print("\n| scene | size | phase | ms | ratio | / largest bound |\n|---|---|---|---:|---:|---:|")
for x in high:
    print(
        f"| {x['scene']} | {x['size']} | {x['phase'][:60]} | {x['ms']:.4f} | {x['ratio']:.2f} "
        f"| {x['ms'] / x['bound']:.2f} |"
    )
pred = [x["predicted"] / x["ms"] for x in rows if x["predicted"] and x["ms"] > 0]
inside = sum(1 for v in pred if 0.75 <= v <= 1.25)
print(
    f"\ncost model: {inside} of {len(pred)} phases predicted within ±25 %, "
    f"median predicted / measured {statistics.median(pred):.2f}"
)
by_kind = {}
for x in rows:
    if x["predicted"] and x["ms"] > 0:
        by_kind.setdefault(x["kind"], []).append(x["predicted"] / x["ms"])
print("\n| phase kind | phases | within ±25 % | median predicted / measured | range |\n|---|---:|---:|---:|---|")
for k, v in sorted(by_kind.items()):
    n = sum(1 for r in v if 0.75 <= r <= 1.25)
    print(f"| {k} | {len(v)} | {n} | {statistics.median(v):.2f} | {min(v):.2f}-{max(v):.2f} |")
