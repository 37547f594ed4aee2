#!/bin/bash
# Ablation: ray-exact's fixed per-pixel cost (iteration cap 0), without the beam, both.
for f in .gl/*.deb; do dpkg -x $f /; done; ldconfig
gunzip -c devexp/strata.gz > /tmp/strata; chmod +x /tmp/strata
export STRATA_CACHE_DIR=/tmp/strata-cache
S=/tmp/strata
VS="${VS:-none cap0 nobeam cap0nobeam none2}"
for v in $VS; do
  f=devexp/${v%2}.txt
  STRATA_SHADER_SED_FILE=$f timeout 200 $S compare --frames 20 --methods ray-exact --no-edits --out /tmp/$v >> $OUT/log.txt 2>&1
  STRATA_SHADER_SED_FILE=$f timeout 200 $S compare --frames 20 --methods ray-exact --no-edits --no-shadows --out /tmp/$v-ns >> $OUT/log.txt 2>&1
done
cd /tmp; VS="$VS" python3 - > $OUT/summary.txt <<'PY'
import json,glob,os
for v in os.environ['VS'].split():
  for s in ['', '-ns']:
    f=glob.glob(f'/tmp/{v}{s}/results-*.json')
    if not f: print(v,s,'missing'); continue
    rs=json.load(open(f[0]))['rows']
    for m in dict.fromkeys(x['method'] for x in rs):
        mr=[x for x in rs if x['method']==m]
        passes={}
        for x in mr:
            for p in x['passes']: passes[p['label']]=passes.get(p['label'],0)+p['mean_ms']/len(mr)
        print(f"{v}{s} {m}: ms {sum(x['gpu_ms_mean'] for x in mr)/len(mr):.4f} flip {sum(x['flip']['mean'] for x in mr)/len(mr):.4f} passes {{{', '.join(f'{k}: {v:.4f}' for k,v in passes.items())}}}")
PY
cat $OUT/summary.txt
