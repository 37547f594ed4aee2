import json,glob,collections,sys
for f in sys.argv[1:]:
    r=json.load(open(f)); rs=[x for x in r['rows'] if x['method']=='ray-exact']
    p=collections.defaultdict(list)
    if not rs:
        print(f,'failed',str(r.get('failures'))[:300]); continue
    for x in rs:
        for q in x['passes']: p[q['label'].replace('ray-exact ','')].append(q['mean_ms'])
    print(f.split('/')[-2] if f.split('/')[-1].startswith('results') else f.split('/')[-1], 'frame', round(sum(x['gpu_ms_mean'] for x in rs)/len(rs),4), {k:round(sum(v)/len(v),4) for k,v in p.items()}, 'see', max(x['see_through'] for x in rs), 'flip', max(x.get('flip_mean',0) or 0 for x in rs))
