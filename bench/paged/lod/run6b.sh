#!/bin/bash
# Device run 6b (same lease as 6a, which made the store): the twelve views at far 16384 against the CPU reference.
for f in .gl/*.deb; do dpkg -x $f /; done; ldconfig
S=./devbin/strata
export STRATA_CACHE_DIR=/tmp/strata-cache
W=/tmp/fs/world-65536x65536
# The twelve views at far 16384, 640x400 (focal 512 as at any size: the same per-pixel level of detail).
$S render --level $W --method ray-exact --far 16384 --size 640x400 --frames 10 --json --out /tmp/rh > $OUT/render-horizon.jsonl 2> $OUT/render-horizon.err
( /usr/bin/time -v timeout 420 $S reference --level $W --far 16384 --size 640x400 --no-cache --json --out /tmp/refh ) > $OUT/reference-horizon.jsonl 2> $OUT/reference-horizon-time.txt
for v in $(ls /tmp/rh | grep -v json); do echo "$v $($S metrics --reference /tmp/refh/$v --render /tmp/rh/$v --json)"; done > $OUT/metrics-horizon.txt 2>&1
ls -la $OUT
