#!/usr/bin/env bash
# The README's side-by-side table in one H100 call: both halves of
# `../h100-1207/run-half.sh` (HALF=1 ray, voxel, sliced and Strata's compute
# methods; HALF=2 scattered, painted, mesh), one after the other, each
# half's files in a tarball (a call brings back at most 8 files). Carry
# .gl, devbin (strata.xz) and devbin-vange.
#   OUT=$OUT bash bench/issue36-vange/h100-1207b/run-both.sh
set -u
for half in 1 2; do
    mkdir -p "/tmp/half$half"
    OUT=/tmp/half$half HALF=$half bash bench/issue36-vange/h100-1207/run-half.sh > "$OUT/half$half.txt" 2>&1
    (cd /tmp && tar czf "$OUT/half$half.tgz" "half$half")
    cat "$OUT/half$half.txt"
done
