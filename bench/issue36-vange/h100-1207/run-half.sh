#!/usr/bin/env bash
# 2026-12-07: the README's side-by-side table rerun at one Strata revision,
# in two H100 calls (a call has 10 minutes): HALF=1 ray, voxel, sliced (and
# Strata's compute methods), HALF=2 scattered, painted, mesh.
# Carry .gl, devbin (strata.xz) and devbin-vange.
#   OUT=$OUT HALF=1 bash bench/issue36-vange/h100-1207/run-half.sh
set -u
for f in .gl/*.deb; do dpkg -x "$f" /; done; ldconfig
python3 -c 'import lzma, sys; sys.stdout.buffer.write(lzma.open(sys.argv[1]).read())' devbin/strata.xz > devbin/strata
chmod +x devbin/strata devbin-vange/level
export VANGE_WARMUP=10
if [ "${HALF:-1}" = 1 ]; then
    export STRATA_METHODS=ray:128,voxel,sliced:512,ray-exact,ray-compute,voxel-compute
    export VANGE_TERRAINS="ray:128=RayTraced,--ray-steps,128 voxel=RayVoxelTraced,--voxel-size,4,8,2,--voxel-steps,100 sliced:512=Sliced,--slice-layers,512"
else
    export STRATA_METHODS=scattered,painted,mesh:0.5
    export VANGE_TERRAINS="scattered=Scattered,--scatter-density,4,4,4 painted=Painted mesh:0.5=Mesh,--mesh-quality,0.5"
fi
start=$(date +%s)
OUTH=$OUT
OUT=$OUTH/side timeout 570 bash bench/issue36-vange/run.sh > "$OUTH/side.log" 2>&1
echo "side rc $? after $(( $(date +%s) - start )) s" >> "$OUTH/side.log"
tail -3 "$OUTH/side.log"
cat "$OUTH/side/table.md"
