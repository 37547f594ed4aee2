#!/bin/bash
# Device run 9: strata video over the 65536^2 store through pages (issue 33), and the physics toy at the exact surface (issue 35).
for f in .gl/*.deb; do dpkg -x $f /; done; ldconfig
S=./devbin/strata
export STRATA_CACHE_DIR=/tmp/strata-cache
W=/tmp/fs/world-65536x65536
$S --version > $OUT/version.txt
[ -f $W/zarr.json ] || ( /usr/bin/time -v $S generate --size 65536x65536 --to store --out $W ) > $OUT/gen65k.txt 2>&1
( /usr/bin/time -v $S video --level $W --methods ray-exact,mesh --frames-dir /tmp/v65 --fps 10 --duration 6 ) > $OUT/video65k.txt 2>&1
cp /tmp/v65/video.json $OUT/video65k.json 2>/dev/null
$S collide --physics-bench --bodies 100,1000 --json > $OUT/physics.json 2>&1
ls -la $OUT
