#!/bin/bash
# The pyramid as a texture: R8Uint mips (tex) or R32Uint texels of 2x2 tiles (tex32, what a WebGPU storage build could write), against the shipped buffer (none).
for f in .gl/*.deb; do dpkg -x $f /; done; ldconfig
gunzip -c devexp/strata.gz > /tmp/strata; chmod +x /tmp/strata
export STRATA_CACHE_DIR=/tmp/strata-cache
S=/tmp/strata
V="none tex tex32 none2 tex2 tex322 4k-none 4k-tex 4k-tex32"
for v in $V; do
  k=${v#4k-}; k=${k%2}; [ $k = tex3 ] && k=tex32
  case $k in
    none) E="STRATA_SHADER_SED_FILE=devexp/none.txt" ;;
    tex) E="STRATA_EXP_PYRAMID=tex STRATA_SHADER_SED_FILE=devexp/piptex.txt" ;;
    tex32) E="STRATA_EXP_PYRAMID=tex32 STRATA_SHADER_SED_FILE=devexp/piptex32.txt" ;;
  esac
  A=""; case $v in 4k-*) A="--size 3840x2160";; esac
  env $E timeout 100 $S compare --frames 20 $A --methods ray-exact --no-edits --out /tmp/$v >> $OUT/log.txt 2>&1
done
cd /tmp; V="$V" python3 - > $OUT/summary.txt <<'PY'
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
cat $OUT/summary.txt; grep -i "error\|EXP_" $OUT/log.txt | sort | uniq -c | head -8
