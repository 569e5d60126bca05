#!/usr/bin/env python3
"""Counts the phases of `bench scene --json` outputs (bs_NAME.txt in FOLDER) that the cost model
predicts within ±25 %: as recorded (`predicted_ms`, "new") and as the noon model would have
from the same counts and constants ("old": every draw a dependent pass, no vertices, a frame's
triangle bytes charged beside its fragments), in all and by kind of phase; then each render's
two predictions over its time.

    python3 noon_model.py FOLDER
"""
import json,glob,os,sys,statistics
folder=sys.argv[1]
res={'new':[], 'old':[]}
kinds={}
for f in sorted(glob.glob(folder+"/bs_*.txt")):
    for r in json.load(open(f))['records']:
        c=r['constants']; fr=c['frame']
        for p in r['phases']:
            d=p['drawn']; s=d['stats']; m=p['ms']
            if not m>0: continue
            frag=d.get('fragments')
            base=s['fetches']*1e-6*c['ms_per_m_fetches']
            if frag is not None:
                old=s['draws']*c['fixed_ms']+s['bytes_written']*1e-6*c['ms_per_mb_written']+base+s['points']*1e-6*fr['ms_per_m_points']+frag*1e-6*fr['ms_per_m_fragments']
            else:
                old=s['draws']*c['fixed_ms']+s['bytes_written']*1e-6*c['ms_per_mb_written']+base+s['points']*1e-6*c['ms_per_m_points']
            new=p['predicted_ms']
            k=p['phase'].split(' ')[0].split(':')[0]
            for name,v in (('new',new/m),('old',old/m)):
                res[name].append(v)
                kinds.setdefault((k,name),[]).append(v)
for name,v in res.items():
    print(name, sum(1 for x in v if 0.75<=x<=1.25), 'of', len(v), 'median', round(statistics.median(v),2))
for (k,name),v in sorted(kinds.items()):
    print(f"{k:14} {name} {sum(1 for x in v if 0.75<=x<=1.25)}/{len(v)} median {statistics.median(v):.2f}")
print()
for f in sorted(glob.glob(folder+"/bs_*.txt")):
    for r in json.load(open(f))['records']:
        c=r['constants']; fr=c['frame']
        for p in r['phases']:
            d=p['drawn']; s=d['stats']; m=p['ms']; frag=d.get('fragments')
            if frag is None or not p['phase'].startswith('render'): continue
            old=s['draws']*c['fixed_ms']+s['bytes_written']*1e-6*c['ms_per_mb_written']+s['points']*1e-6*fr['ms_per_m_points']+frag*1e-6*fr['ms_per_m_fragments']
            print(f"{f.split('/')[-1][3:-4]:12} {int(r['particles']**.5):5} new {p['predicted_ms']/m:.2f} old {old/m:.2f}")
