#!/bin/bash
# Device run 30: ray-exact's beam pre-pass (limit branch) on/off in one binary, and the old binary (08330a0) as baseline; 12 views, 1280x800, shadows; plus --no-shadows.
for f in .gl/*.deb; do dpkg -x $f /; done; ldconfig
mkdir -p /tmp/bin; for f in devbin/*.gz; do gunzip -c $f > /tmp/bin/$(basename $f .gz); chmod +x /tmp/bin/$(basename $f .gz); done
export STRATA_CACHE_DIR=/tmp/strata-cache
B=/tmp/bin
C="compare --methods ray-exact --no-edits --frames 20"
for i in 1 2; do
  $B/strata-old $C --out /tmp/o-$i >> $OUT/log.txt 2>&1; cp /tmp/o-$i/results-*.json $OUT/old-$i.json
  for b in on off; do STRATA_EXACT_BEAM=$b $B/strata $C --out /tmp/c-$b-$i >> $OUT/log.txt 2>&1; cp /tmp/c-$b-$i/results-*.json $OUT/beam-$b-$i.json; done
done
for b in on off; do STRATA_EXACT_BEAM=$b $B/strata $C --no-shadows --out /tmp/n-$b >> $OUT/log.txt 2>&1; cp /tmp/n-$b/results-*.json $OUT/noshadows-$b.json; done
$B/strata --version >> $OUT/log.txt; $B/strata-old --version >> $OUT/log.txt
