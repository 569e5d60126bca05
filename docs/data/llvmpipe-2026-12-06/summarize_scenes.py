# Medians over the rounds of each scene's frame_ms, a6632bd against the head: python3 sum.py DIR
import json,glob,statistics as st,sys,collections
d=sys.argv[1]; ms=collections.defaultdict(list)
for f in glob.glob(d+'/*_*_*.json'):
    name=f.split('/')[-1][:-5]; s,v,r=name.rsplit('_',2)
    try: rec=json.load(open(f))['records'][0]
    except Exception: continue
    ms[(s,v)].append(rec['frame_ms'])
print("| scene | frame ms a6632bd | head | head / a6632bd | rounds |"); print("|---|---:|---:|---:|---:|")
for s in sorted({k[0] for k in ms}):
    o,n=ms.get((s,'old')),ms.get((s,'new'))
    if o and n: print(f"| {s} | {st.median(o):.3f} | {st.median(n):.3f} | {st.median(n)/st.median(o):.2f} | {min(len(o),len(n))} |")
