#!/bin/bash
# Experiment: the max pyramid's layout (row-major bytes as shipped; 8x4 / 16x8 byte tiles; an R8Uint mip texture).
for f in .gl/*.deb; do dpkg -x $f /; done; ldconfig
gunzip -c devexp/strata.gz > /tmp/strata; chmod +x /tmp/strata
export STRATA_CACHE_DIR=/tmp/strata-cache
S=/tmp/strata
for v in none tex tile tile16 row none2 tex2 tile2; do
  case $v in
    none*) env STRATA_SHADER_SED_FILE=devexp/none.txt timeout 100 $S compare --frames 20 --methods ray-exact --no-edits --out /tmp/$v >> $OUT/log.txt 2>&1 ;;
    *) k=${v%2}; env STRATA_EXP_PYRAMID=$k STRATA_SHADER_SED_FILE=devexp/pip$k.txt timeout 100 $S compare --frames 20 --methods ray-exact --no-edits --out /tmp/$v >> $OUT/log.txt 2>&1 ;;
  esac
done
cd /tmp; python3 - > $OUT/summary.txt <<'PY'
import json,glob
for v in ['none','tex','tile','tile16','row','none2','tex2','tile2']:
    f=glob.glob(f'/tmp/{v}/results-*.json')
    if not f: print(v,'missing'); continue
    rs=json.load(open(f[0]))['rows']
    passes={}
    for x in rs:
        for p in x['passes']: passes[p['label']]=passes.get(p['label'],0)+p['mean_ms']/len(rs)
    print(f"{v} ray-exact: ms {sum(x['gpu_ms_mean'] for x in rs)/len(rs):.4f} flip {sum(x['flip']['mean'] for x in rs)/len(rs):.4f} passes {{{', '.join(f'{k}: {v:.4f}' for k,v in passes.items())}}}")
PY
cat $OUT/summary.txt; grep -i "error\|EXP_PYR" $OUT/log.txt | sort | uniq -c | head -8
