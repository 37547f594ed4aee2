#!/bin/bash
# Device call A: issue 36's side-by-side with vange-rs (bench/issue36-vange/run.sh), plus main@a8d72b3 (devbin/strata-exp.gz) as the baseline binary.
for f in .gl/*.deb; do dpkg -x $f /; done; ldconfig
gunzip -c devbin/strata.gz > devbin/strata; chmod +x devbin/strata; gunzip -f devbin-vange/level.gz; chmod +x devbin-vange/level
gunzip -c devbin/strata-exp.gz > /tmp/strata-base; chmod +x /tmp/strata-base
export STRATA_METHODS="ray:128,ray:128/nobeam,voxel,voxel:/nobeam,sliced:512,scattered,painted,mesh:0.5,mesh:0.5/fragment,ray-exact"
export VANGE_TERRAINS="ray:128=RayTraced,--ray-steps,128 voxel=RayVoxelTraced,--voxel-size,4,8,2,--voxel-steps,100 sliced:512=Sliced,--slice-layers,512 scattered=Scattered painted=Painted"
export VANGE_WARMUP=10
OUTA=$OUT
OUT=$OUTA/side timeout 420 bash bench/issue36-vange/run.sh > $OUTA/side.log 2>&1
echo "side rc $?" >> $OUTA/side.log
export STRATA_CACHE_DIR=/tmp/strata-cache
/tmp/strata-base generate --out /tmp/w >/dev/null 2>&1
timeout 100 /tmp/strata-base compare --level /tmp/w --vange-rs-mid --no-edits --frames 20 --methods mesh:0.5,ray:128,voxel --out /tmp/base > $OUTA/base.log 2>&1
cp /tmp/base/results-*.json $OUTA/results-base-a8d72b3.json
cat $OUTA/side/table.md
