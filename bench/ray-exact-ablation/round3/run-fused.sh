#!/bin/bash
# The deferred march casting its workgroups' first-stamped shadow blocks (fused) against the baseline binary (base).
for f in .gl/*.deb; do dpkg -x $f /; done; ldconfig
gunzip -c devexp/strata.gz > /tmp/strata; chmod +x /tmp/strata
gunzip -c devexp/base.gz > /tmp/base; chmod +x /tmp/base
export STRATA_CACHE_DIR=/tmp/strata-cache
V="base fused base2 fused2"
for v in $V; do
  case ${v%2} in base) S=/tmp/base ;; fused) S=/tmp/strata ;; esac
  timeout 100 $S compare --frames 20 --methods ray-exact --no-edits --out /tmp/$v >> $OUT/log.txt 2>&1
done
for v in base fused; do
  case $v in base) S=/tmp/base ;; fused) S=/tmp/strata ;; esac
  timeout 100 $S compare --frames 20 --size 3840x2160 --methods ray-exact --no-edits --out /tmp/4k-$v >> $OUT/log.txt 2>&1
done
cd /tmp; V="$V 4k-base 4k-fused" python3 - > $OUT/summary.txt <<'PY'
import json,glob,os
for v in os.environ['V'].split():
    f=glob.glob(f'/tmp/{v}/results-*.json')
    if not f: print(v,'missing'); continue
    rs=json.load(open(f[0]))['rows']
    passes={}
    for x in rs:
        for p in x['passes']: passes[p['label']]=passes.get(p['label'],0)+p['mean_ms']/len(rs)
    print(f"{v} ray-exact: ms {sum(x['gpu_ms_mean'] for x in rs)/len(rs):.4f} flip {sum(x['flip']['mean'] for x in rs)/len(rs):.4f} passes {{{', '.join(f'{k}: {v:.4f}' for k,v in passes.items())}}}")
PY
cat $OUT/summary.txt; grep -i "error\|panic" $OUT/log.txt | sort | uniq -c | head -8
cp /tmp/fused/report.md $OUT/report-fused.md
