#!/bin/bash
# Device call B: ray-exact's beam searches A/B (one binary), the gameplay workload (issue 35), the collider, vange-rs's Mesh beside Strata's mesh.
for f in .gl/*.deb; do dpkg -x $f /; done; ldconfig
gunzip -c devbin/strata.gz > devbin/strata; chmod +x devbin/strata; gunzip -f devbin-vange/level.gz; chmod +x devbin-vange/level
S=devbin/strata
export STRATA_CACHE_DIR=/tmp/strata-cache
for b in off serial wide wide-pass serial wide-pass; do
  STRATA_EXACT_BEAM=$b timeout 60 $S compare --methods ray-exact --no-edits --frames 20 --out /tmp/rx-$b >> $OUT/log.txt 2>&1
  cp /tmp/rx-$b/results-*.json /tmp/res-rx-$b-$RANDOM.json
done
STRATA_EXACT_SHADOW_ROUNDS=1 timeout 60 $S compare --methods ray-exact --no-edits --frames 20 --out /tmp/rx-s1 >> $OUT/log.txt 2>&1
cp /tmp/rx-s1/results-*.json /tmp/res-rx-wide-pass-shadow1.json
timeout 200 $S compare --no-edits --frames 20 --methods mesh:0.5,ray-exact,voxel-compute --view-names hangar --gameplay 64 --out /tmp/gp >> $OUT/log.txt 2>&1
cp /tmp/gp/results-*.json $OUT/results-gameplay.json; cp /tmp/gp/report.md $OUT/report-gameplay.md
timeout 60 $S collide --json > $OUT/collide-h100.json 2>> $OUT/log.txt
cd /tmp; python3 - > $OUT/summary.txt <<'PY'
import json,glob,collections
for f in sorted(glob.glob('/tmp/res-rx-*.json')):
    r=json.load(open(f)); rs=[x for x in r['rows'] if x['method']=='ray-exact']
    if not rs: print(f,'failed'); continue
    p=collections.defaultdict(list)
    for x in rs:
        for q in x['passes']: p[q['label'].replace('ray-exact ','')].append(q['mean_ms'])
    print(f.split('/')[-1], 'frame', round(sum(x['gpu_ms_mean'] for x in rs)/len(rs),4), {k:round(sum(v)/len(v),4) for k,v in p.items()}, 'see', max(x['see_through'] for x in rs))
PY
cd - >/dev/null
tar czf $OUT/rx.tgz -C /tmp $(cd /tmp && ls res-rx-*.json)
OUTB=$OUT
OUT=$OUTB/side-mesh STRATA_METHODS=mesh:0.5 VANGE_TERRAINS="mesh:0.5=Mesh,--mesh-quality,0.5" VANGE_WARMUP=10 timeout 230 bash bench/issue36-vange/run.sh > $OUTB/side-mesh.log 2>&1
cat $OUTB/summary.txt; cat $OUTB/side-mesh/table.md
