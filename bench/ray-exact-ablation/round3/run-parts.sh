#!/bin/bash
# The deferred shadow pass marching each texel's ray in 2 or 4 parts at once (p2, p4) against the baseline binary (base).
for f in .gl/*.deb; do dpkg -x $f /; done; ldconfig
for b in base strata2 strata4; do xz -dc devexp/$b.xz > /tmp/$b.bin; chmod +x /tmp/$b.bin; done
export STRATA_CACHE_DIR=/tmp/strata-cache
V="base p2 p4 base2 p22 p42 4k-base 4k-p2 4k-p4"
for v in $V; do
  k=${v#4k-}; case $k in base*) S=/tmp/base.bin;; p2*) S=/tmp/strata2.bin;; p4*) S=/tmp/strata4.bin;; esac
  A=""; case $v in 4k-*) A="--size 3840x2160";; esac
  timeout 100 $S compare --frames 20 $A --methods ray-exact --no-edits --out /tmp/$v >> $OUT/log.txt 2>&1
done
python3 devexp/summarise.py $V > $OUT/summary.txt
cat $OUT/summary.txt; grep -i "error\|panic" $OUT/log.txt | sort | uniq -c | head -8
