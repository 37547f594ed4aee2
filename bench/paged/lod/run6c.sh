#!/bin/bash
# Device run 6c: the twelve views raised 200 texels over the ground and looking 6 degrees down, far 16384:
# against the CPU reference at 640x400 (focal 512: the same per-pixel level of detail as 1280x800), timed at 1280x800.
for f in .gl/*.deb; do dpkg -x $f /; done; ldconfig
S=./devbin/strata
W=/tmp/fs/world-65536x65536
V=devbin/horizon-views.txt
$S render --level $W --views $V --method ray-exact --far 16384 --size 640x400 --frames 10 --json --out /tmp/rhh > $OUT/render-high.jsonl 2> $OUT/render-high.err
$S render --level $W --views $V --method ray-exact --far 16384 --size 640x400 --frames 10 --lod-pixels 0 --gpu-budget 1GiB --json --out /tmp/rhh0 > $OUT/render-high-nolod.jsonl 2>> $OUT/render-high.err
( /usr/bin/time -v timeout 500 $S reference --level $W --views $V --far 16384 --size 640x400 --no-cache --json --out /tmp/refhh ) > $OUT/reference-high.jsonl 2> $OUT/reference-high-time.txt
for v in $(ls /tmp/rhh | grep -v json); do echo "$v $($S metrics --reference /tmp/refhh/$v --render /tmp/rhh/$v --json) $($S metrics --reference /tmp/refhh/$v --render /tmp/rhh0/$v --json)"; done > $OUT/metrics-high.txt 2>&1
$S render --level $W --views $V --method ray-exact --far 16384 --frames 20 --json --out /tmp/rhh1280 > $OUT/render-high-1280.jsonl 2>> $OUT/render-high.err
ls -la $OUT
