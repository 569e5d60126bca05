"""Cost model by kind of phase: predicted / measured, per binary.

Usage: python3 bykind.py DIR BIN [BIN...]  (DIR as for compare.py). Prints, per kind and binary,
the phase-runs, how many are within ±25 % and the median; then the frame's price of a cleared
texel, and the tried range start (H only), over the runs that have them.
"""
import json,glob,statistics as st,collections,sys
D,bins=sys.argv[1],sys.argv[2:]
g=collections.defaultdict(lambda: collections.defaultdict(list))
cl=[]
rg=[]
for b in bins:
  for f in glob.glob(f'{D}/{b}/r*/*.json'):
    for r in json.load(open(f))['records']:
      fr=r['constants'].get('frame') or {}
      if 'ms_per_m_cleared' in fr: cl.append(fr['ms_per_m_cleared'])
      if 'range_ms' in r['constants']: rg.append(r['constants']['range_ms'])
      for p in r['phases']:
        pr=p.get('predicted_ms')
        if not pr: continue
        k=p['phase'].split(':')[0].split('(')[0].strip()
        if k.startswith('sort network'): k='sort network'
        if k.startswith('gather'): k='gather'
        g[k][b].append(pr/p['ms'])
for k,v in sorted(g.items()):
  print(f"{k:22s}", ' '.join(f"{b}: n={len(v[b])} within={sum(1 for x in v[b] if .75<=x<=1.25):2d} med={st.median(v[b]):.2f}" for b in bins))
if cl: print('ms per million texels cleared: min %.3f median %.3f max %.3f' % (min(cl), st.median(cl), max(cl)))
if rg: print('ms a timed range starts (binary H): min %.4f median %.4f max %.4f' % (min(rg), st.median(rg), max(rg)))
