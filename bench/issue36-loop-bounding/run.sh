#!/bin/bash
# Issue 36: naga's forced loop bounding off (the default now) against on
# (STRATA_SHADER_LOOP_BOUNDING=on), one binary, one call: every method once
# each way, then ray-exact's protocol twice each way.
for f in .gl/*.deb; do dpkg -x $f /; done; ldconfig
gunzip -c devexp/strata.gz > /tmp/strata; chmod +x /tmp/strata
export STRATA_CACHE_DIR=/tmp/strata-cache
S=/tmp/strata
for v in all-off all-on; do
  E=""; [ ${v#all-} = on ] && E="STRATA_SHADER_LOOP_BOUNDING=on"
  echo "== $v: $E" >> $OUT/log.txt
  env $E timeout 200 $S compare --frames 20 --no-edits --out /tmp/$v >> $OUT/log.txt 2>&1
  cp /tmp/$v/results-*.json $OUT/results-$v.json
done
for v in exact-off exact-on exact-off2 exact-on2; do
  E=""; case $v in exact-on*) E="STRATA_SHADER_LOOP_BOUNDING=on";; esac
  echo "== $v: $E" >> $OUT/log.txt
  env $E timeout 70 $S compare --frames 20 --methods ray-exact --no-edits --out /tmp/$v >> $OUT/log.txt 2>&1
done
python3 devexp/summary_all.py all-off all-on exact-off exact-on exact-off2 exact-on2 > $OUT/summary.txt
cat $OUT/summary.txt; grep -i "error\|panic\|refus" $OUT/log.txt | sort | uniq -c | head -8
