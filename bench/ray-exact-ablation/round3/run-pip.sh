#!/bin/bash
# Experiment: the max pyramid's layout (row-major bytes as shipped; 8x4 / 16x8 byte tiles; an R8Uint mip texture).
for f in .gl/*.deb; do dpkg -x $f /; done; ldconfig
gunzip -c devexp/strata.gz > /tmp/strata; chmod +x /tmp/strata
export STRATA_CACHE_DIR=/tmp/strata-cache
S=/tmp/strata
V="none tex tile tile16 row none2 tex2 tile2"
for v in $V; do
  case $v in
    none*) env STRATA_SHADER_SED_FILE=devexp/none.txt timeout 100 $S compare --frames 20 --methods ray-exact --no-edits --out /tmp/$v >> $OUT/log.txt 2>&1 ;;
    *) k=${v%2}; env STRATA_EXP_PYRAMID=$k STRATA_SHADER_SED_FILE=devexp/pip$k.txt timeout 100 $S compare --frames 20 --methods ray-exact --no-edits --out /tmp/$v >> $OUT/log.txt 2>&1 ;;
  esac
done
python3 devexp/summarise.py $V > $OUT/summary.txt
cat $OUT/summary.txt; grep -i "error\|EXP_PYR" $OUT/log.txt | sort | uniq -c | head -8
