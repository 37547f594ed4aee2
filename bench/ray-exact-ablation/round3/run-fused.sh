#!/bin/bash
# The deferred march casting its workgroups' first-stamped shadow blocks (fused) against the baseline binary (base).
for f in .gl/*.deb; do dpkg -x $f /; done; ldconfig
gunzip -c devexp/strata.gz > /tmp/strata; chmod +x /tmp/strata
gunzip -c devexp/base.gz > /tmp/base; chmod +x /tmp/base
export STRATA_CACHE_DIR=/tmp/strata-cache
V="base fused base2 fused2"
for v in $V; do
  case ${v%2} in base) S=/tmp/base ;; fused) S=/tmp/strata ;; esac
  timeout 100 $S compare --frames 20 --methods ray-exact --no-edits --out /tmp/$v >> $OUT/log.txt 2>&1
done
for v in base fused; do
  case $v in base) S=/tmp/base ;; fused) S=/tmp/strata ;; esac
  timeout 100 $S compare --frames 20 --size 3840x2160 --methods ray-exact --no-edits --out /tmp/4k-$v >> $OUT/log.txt 2>&1
done
python3 devexp/summarise.py $V 4k-base 4k-fused > $OUT/summary.txt
cat $OUT/summary.txt; grep -i "error\|panic" $OUT/log.txt | sort | uniq -c | head -8
cp /tmp/fused/report.md $OUT/report-fused.md
