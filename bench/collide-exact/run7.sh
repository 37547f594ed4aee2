#!/bin/bash
# Device run 7: the exact collider (issue 35) and compare over paged terrain (issue 33).
for f in .gl/*.deb; do dpkg -x $f /; done; ldconfig
S=./devbin/strata
export STRATA_CACHE_DIR=/tmp/strata-cache
$S --version > $OUT/version.txt
$S collide --json > $OUT/collide.json 2> $OUT/collide.err
$S collide --rays 100000 --edits 64 > $OUT/collide-100k.txt 2>&1
$S collide --physics-bench --bodies 100,1000 --json > $OUT/physics.json 2> $OUT/physics.err
$S collide --physics-bench --bodies 100,1000 --surface-step 2 --json > $OUT/physics-step2.json 2>> $OUT/physics.err
# compare whole vs paged on the default world (no edits: the paged rows skip the edit protocol)
$S compare --no-edits --methods ray-exact,ray-exact-fragment,ray --out /tmp/cmp-whole > $OUT/cmp-whole.txt 2>&1
$S compare --no-edits --methods ray-exact,ray-exact-fragment,ray --gpu-budget 256MiB --out /tmp/cmp-paged > $OUT/cmp-paged.txt 2>&1
cp /tmp/cmp-whole/report.md $OUT/cmp-whole.md; cp /tmp/cmp-paged/report.md $OUT/cmp-paged.md
ls -la $OUT
