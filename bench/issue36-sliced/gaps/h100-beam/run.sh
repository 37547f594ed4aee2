#!/bin/bash
# Device run 56 (H100): the per-pixel walks of sliced from the beam start (56f2174) against /nobeam, one binary, alternating; the gameplay workload for the refined slicer.
for f in .gl/*.deb; do dpkg -x $f /; done; ldconfig
gunzip -c devbin/strata-head.gz > /tmp/strata; chmod +x /tmp/strata
export STRATA_CACHE_DIR=/tmp/strata-cache
S=/tmp/strata
$S --version > $OUT/log.txt
M=sliced:512,sliced:512/nobeam,sliced:512/refine,sliced:512/refine/nobeam
$S compare --frames 20 --methods $M --no-edits --out /tmp/a >> $OUT/log.txt 2>&1
$S compare --frames 20 --methods $M --no-edits --out /tmp/b >> $OUT/log.txt 2>&1
timeout 200 $S compare --gameplay --methods sliced:512/refine,sliced:512 --view-names hangar --frames 20 --out /tmp/gp >> $OUT/log.txt 2>&1
sed -n '/Gameplay edits/,/^Collider/p' /tmp/gp/report.md > $OUT/gameplay.md
cd /tmp; python3 - > $OUT/summary.txt <<'PY'
import json,glob
for v in ['a','b']:
    rs=json.load(open(glob.glob(f'/tmp/{v}/results-*.json')[0]))['rows']
    for m in dict.fromkeys(x['method'] for x in rs):
        mr=[x for x in rs if x['method']==m]
        passes={}
        for x in mr:
            for p in x['passes']: passes[p['label']]=passes.get(p['label'],0)+p['mean_ms']/len(mr)
        print(f"{v} {m}: ms {sum(x['gpu_ms_mean'] for x in mr)/len(mr):.3f} see max {max(x['see_through'] for x in mr):.3f} flip {sum(x['flip']['mean'] for x in mr)/len(mr):.4f} coh {sum(x['coherence'] for x in mr)/len(mr):.3f} bytes {mr[0]['gpu_bytes']} passes {{{', '.join(f'{k}: {v:.3f}' for k,v in passes.items())}}}")
PY
cp /tmp/a/results-*.json $OUT/results.json
cat $OUT/summary.txt $OUT/gameplay.md
