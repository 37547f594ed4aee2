#!/bin/bash
# Leaf reject experiment: column_entry returns at once when the segment stays above the column's top (bit-identical on lavapipe).
for f in .gl/*.deb; do dpkg -x $f /; done; ldconfig
gunzip -c devexp/strata.gz > /tmp/strata; chmod +x /tmp/strata
export STRATA_CACHE_DIR=/tmp/strata-cache
S=/tmp/strata
nvidia-smi --query-gpu=name,driver_version --format=csv > $OUT/log.txt
M=${M:-ray-exact,ray,voxel,sliced:512}
for r in 1 2; do for v in none entry; do
  STRATA_SHADER_SED_FILE=devexp/$v.txt timeout 250 $S compare --frames 20 --methods $M --no-edits --out /tmp/$v-$r >> $OUT/log.txt 2>&1
done; done
cd /tmp; python3 - > $OUT/summary.txt <<'PY'
import json,glob
for r in ['1','2']:
  for v in ['none','entry']:
    f=glob.glob(f'/tmp/{v}-{r}/results-*.json')
    if not f: print(v,r,'missing'); continue
    rs=json.load(open(f[0]))['rows']
    for m in dict.fromkeys(x['method'] for x in rs):
        mr=[x for x in rs if x['method']==m]
        passes={}
        for x in mr:
            for p in x['passes']: passes[p['label']]=passes.get(p['label'],0)+p['mean_ms']/len(mr)
        print(f"{r} {v} {m}: ms {sum(x['gpu_ms_mean'] for x in mr)/len(mr):.4f} flip {sum(x['flip']['mean'] for x in mr)/len(mr):.4f} see {max(x['see_through'] for x in mr):.3f} passes {{{', '.join(f'{k}: {v:.4f}' for k,v in passes.items())}}}")
PY
for v in none entry; do cp /tmp/$v-1/results-*.json $OUT/$v-1.json; done
cat $OUT/summary.txt
