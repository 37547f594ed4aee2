#!/bin/bash
# Device call E: voxel with the exact leaf walk, beside vange-rs, and the previous binary (devbin/strata-exp.gz) in the same call.
for f in .gl/*.deb; do dpkg -x $f /; done; ldconfig
gunzip -c devbin/strata.gz > devbin/strata; chmod +x devbin/strata; gunzip -f devbin-vange/level.gz; chmod +x devbin-vange/level
gunzip -c devbin/strata-exp.gz > /tmp/strata-base; chmod +x /tmp/strata-base
OUTE=$OUT
OUT=$OUTE/side-voxel STRATA_METHODS=voxel,voxel:/nobeam,voxel-compute VANGE_TERRAINS="voxel=RayVoxelTraced,--voxel-size,4,8,2,--voxel-steps,100" VANGE_WARMUP=10 timeout 300 bash bench/issue36-vange/run.sh > $OUTE/side-voxel.log 2>&1
export STRATA_CACHE_DIR=/tmp/strata-cache
/tmp/strata-base generate --out /tmp/w >/dev/null 2>&1
timeout 120 /tmp/strata-base compare --level /tmp/w --vange-rs-mid --no-edits --frames 20 --methods voxel,voxel-compute --out /tmp/base > $OUTE/base.log 2>&1
cp /tmp/base/results-*.json $OUTE/results-base-777e917.json
cat $OUTE/side-voxel/table.md
python3 - <<'PY'
import json
r=json.load(open('/tmp/base/results-nvidia-h100-80gb-hbm3.json'))
for m in ['voxel','voxel-compute']:
    rs=[x for x in r['rows'] if x['method']==m]
    print('base', m, round(sum(x['gpu_ms_mean'] for x in rs)/len(rs),3), 'flip', round(sum(x['flip']['mean'] for x in rs)/len(rs),4), 'see', round(max(x['see_through'] for x in rs),3), 'coh', round(sum(x['coherence'] for x in rs)/len(rs),3))
PY
