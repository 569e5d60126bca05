# Medians of the interleaved runs of run.sh: python3 summarize.py DIR
import json,glob,statistics as st,sys,collections
d=sys.argv[1]
ms=collections.defaultdict(list); up={}
for f in glob.glob(d+'/t2_*_*.json'):
    v=f.split('/')[-1].split('_')[1]
    for r in json.load(open(f))['records']:
        k=(r['size'],r['experiment'])
        ms[(v,)+k].append(r['ms']); fd=r['frame_draws'] or {}; up[(v,)+k]=(fd.get('uniform_uploads'), fd.get('draws'))
keys=sorted({k[1:] for k in ms})
print("| size | exp | draws | uploads old/new/nocache | ms old | ms new | ms nocache | new/old | nocache/new |")
for k in keys:
    m={v:st.median(ms[(v,)+k]) for v in ['old','new','nocache'] if (v,)+k in ms}
    u=[up.get((v,)+k,(None,None))[0] for v in ['old','new','nocache']]
    print(f"| {k[0]} | {k[1]} | {up[('new',)+k][1]} | {u[0]}/{u[1]}/{u[2]} | {m['old']:.3f} | {m['new']:.3f} | {m['nocache']:.3f} | {m['new']/m['old']:.3f} | {m['nocache']/m['new']:.3f} |")
