"""Ratios to floors and the cost model across binaries of an ab.sh run.

Usage: python3 compare.py DIR BIN [BIN...]   (DIR holds BIN/rR/NAME.json, as runs.tgz unpacks)

Prints, per binary, how many phases (scene, size, phase) have a median ratio under 0.95 over
the rounds and how many single runs do, how many phases the cost model predicts within ±25 %
(median of the rounds' predicted/measured), then every phase under 0.95 for some binary.
"""
import collections
import glob
import json
import statistics as st
import sys

D, bins = sys.argv[1], sys.argv[2:]
R = collections.defaultdict(lambda: collections.defaultdict(list))
M = collections.defaultdict(lambda: collections.defaultdict(list))
P = collections.defaultdict(lambda: collections.defaultdict(list))
for b in bins:
    for f in glob.glob(f'{D}/{b}/r*/*.json'):
        for r in json.load(open(f))['records']:
            for p in r['phases']:
                k = (r['scene'], r['size'], p['phase'][:40])
                R[k][b].append(p['ratio'])
                M[k][b].append(p['ms'])
                if p.get('predicted_ms'):
                    P[k][b].append(p['predicted_ms'] / p['ms'])
for b in bins:
    under = sum(1 for k in R if st.median(R[k][b]) < 0.95)
    runs = sum(1 for k in R for x in R[k][b] if x < 0.95)
    n = sum(len(R[k][b]) for k in R)
    within = sum(1 for k in P if 0.75 <= st.median(P[k][b]) <= 1.25)
    print(f'{b}: phases with a median ratio under 0.95: {under} of {len(R)}; single runs under: '
          f'{runs} of {n}; cost model within ±25 %: {within} of {len(P)}')
print()
for k in sorted(R):
    if min(st.median(R[k][b]) for b in bins) < 0.95:
        print(k, ' '.join(f'{b}: {st.median(R[k][b]):.2f} [{min(R[k][b]):.2f}-{max(R[k][b]):.2f}]'
                          f' {st.median(M[k][b]):.3f} ms' for b in bins))
