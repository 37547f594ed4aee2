#!/bin/bash
# Device run 53 (H100): plain sliced's gap pass beside vange-rs, against the binary before item 4's walks (84cc295) and the per-fragment walks (/fragwalk), one call; held-out see-through.
for f in .gl/*.deb; do dpkg -x $f /; done; ldconfig
gunzip -c devbin/strata-rows.gz > devbin/strata; chmod +x devbin/strata
gunzip -c devbin/strata-base.gz > /tmp/strata-base; chmod +x /tmp/strata-base
gunzip -f devbin-vange/level.gz; chmod +x devbin-vange/level
nvidia-smi --query-gpu=name,driver_version --format=csv > $OUT/gpu.txt 2>&1
export STRATA_METHODS="sliced:512,sliced:512/fragwalk,sliced:512/refine"
export VANGE_TERRAINS="sliced:512=Sliced,--slice-layers,512"
export VANGE_WARMUP=10
O=$OUT
OUT=/tmp/side timeout 300 bash bench/issue36-vange/run.sh > $O/log.txt 2>&1
echo "side rc $?" >> $O/log.txt
cp /tmp/side/table.md $O/table.md 2>/dev/null; 
OUT=$O
export STRATA_CACHE_DIR=/tmp/strata-cache
S=devbin/strata
for s in 7 9 36; do $S generate --seed $s --out /tmp/w$s >> $OUT/log.txt 2>&1 & done
$S generate --seed 5 --size 512x1024 --out /tmp/s5 >> $OUT/log.txt 2>&1 &
wait
/tmp/strata-base compare --frames 20 --methods sliced:512,sliced:512/refine --no-edits --out /tmp/b-base >> $OUT/log.txt 2>&1
$S compare --frames 20 --methods sliced:512,sliced:512/fragwalk,sliced:512/refine --no-edits --out /tmp/b-new >> $OUT/log.txt 2>&1
/tmp/strata-base compare --frames 20 --methods sliced:512,sliced:512/refine --no-edits --out /tmp/b-base2 >> $OUT/log.txt 2>&1
$S compare --frames 20 --methods sliced:512,sliced:512/fragwalk,sliced:512/refine --no-edits --out /tmp/b-new2 >> $OUT/log.txt 2>&1
cd /tmp; python3 - > $OUT/summary.txt <<'PY'
import json,glob
for v in ['base','new','base2','new2']:
    fs=glob.glob(f'/tmp/b-{v}/results-*.json')
    if not fs: print(v,'missing'); continue
    rs=json.load(open(fs[0]))['rows']
    for m in sorted(set(x['method'] for x in rs)):
        mr=[x for x in rs if x['method']==m]
        print(f"{v} {m}: ms {sum(x['gpu_ms_mean'] for x in mr)/len(mr):.3f} see max {max(x['see_through'] for x in mr):.3f} flip {sum(x['flip']['mean'] for x in mr)/len(mr):.4f} coh {sum(x['coherence'] for x in mr)/len(mr):.3f} p95 {sum(x['depth_p95'] for x in mr)/len(mr):.2f} bytes {mr[0]['gpu_bytes']} | " + ' '.join(f"{x['view']}:{x['gpu_ms_mean']:.2f}" for x in mr))
for w in ['w7','w9','w36','s5']:
    fs=glob.glob(f'/tmp/h-{w}/results-*.json')
    if not fs: print(w,'missing'); continue
    rs=json.load(open(fs[0]))['rows']
    for m in sorted(set(x['method'] for x in rs)):
        mr=[x for x in rs if x['method']==m]
        worst=max(mr,key=lambda x:x['see_through'])
        print(f"held {w} {m}: see max {worst['see_through']:.3f} ({worst['view']}) covers-sky max {max(x['covers_sky'] for x in mr):.3f} coh mean {sum(x['coherence'] for x in mr)/len(mr):.3f}")
PY
cp /tmp/b-base/results-*.json $OUT/results-base-84cc295.json; cp /tmp/b-new/results-*.json $OUT/results-new.json

cat $OUT/summary.txt; cat $OUT/table.md
