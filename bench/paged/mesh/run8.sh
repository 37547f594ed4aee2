#!/bin/bash
# Device run 8: paged mesh at 65536^2 (issue 33): fly and per-view render, ray-exact beside it.
for f in .gl/*.deb; do dpkg -x $f /; done; ldconfig
S=./devbin/strata
export STRATA_CACHE_DIR=/tmp/strata-cache
W=/tmp/fs/world-65536x65536
$S --version > $OUT/version.txt
[ -f $W/zarr.json ] || ( /usr/bin/time -v $S generate --size 65536x65536 --to store --out $W ) > $OUT/gen65k.txt 2>&1
( /usr/bin/time -v $S fly --level $W --method mesh --frames 600 --out /tmp/fly-mesh ) > $OUT/fly-mesh.txt 2>&1
$S fly --level $W --method ray-exact --frames 600 --out /tmp/fly-exact > $OUT/fly-exact.txt 2>&1
$S render --level $W --method mesh --frames 20 --json --out /tmp/rm > $OUT/render-mesh.jsonl 2> $OUT/render-mesh.err
cp /tmp/fly-mesh/fly.json $OUT/fly-mesh.json; cp /tmp/fly-exact/fly.json $OUT/fly-exact.json
# the default world: paged mesh vs whole mesh (same views): identical pictures?
$S render --method mesh --frames 20 --json --out /tmp/mw > $OUT/render-mesh-whole.jsonl 2>> $OUT/render-mesh.err
$S render --method mesh --frames 20 --gpu-budget 256MiB --json --out /tmp/mp > $OUT/render-mesh-paged.jsonl 2>> $OUT/render-mesh.err
for v in $(ls /tmp/mp | grep -v json); do cmp -s /tmp/mp/$v/depth.f32 /tmp/mw/$v/depth.f32 && cmp -s /tmp/mp/$v/color.png /tmp/mw/$v/color.png && echo "$v identical" || echo "$v DIFFERS"; done >> $OUT/fly-mesh.txt
ls -la $OUT
