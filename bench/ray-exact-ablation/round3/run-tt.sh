#!/bin/bash
# Experiment: column tops as an R8Uint texture tested before the pair fetch (topstex); with the pyramid as an R8Uint mip texture (both).
for f in .gl/*.deb; do dpkg -x $f /; done; ldconfig
gunzip -c devexp/strata.gz > /tmp/strata; chmod +x /tmp/strata
export STRATA_CACHE_DIR=/tmp/strata-cache
S=/tmp/strata
V="none tex topstex both none2 topstex2 both2"
for v in $V; do
  k=${v%2}
  case $k in
    none) E="STRATA_SHADER_SED_FILE=devexp/none.txt" ;;
    tex) E="STRATA_EXP_PYRAMID=tex STRATA_SHADER_SED_FILE=devexp/piptex.txt" ;;
    topstex) E="STRATA_EXP_TOPSTEX=1 STRATA_SHADER_SED_FILE=devexp/topstex.txt" ;;
    both) E="STRATA_EXP_TOPSTEX=1 STRATA_EXP_PYRAMID=tex STRATA_SHADER_SED_FILE=devexp/both.txt" ;;
  esac
  env $E timeout 100 $S compare --frames 20 --methods ray-exact --no-edits --out /tmp/$v >> $OUT/log.txt 2>&1
done
python3 devexp/summarise.py $V > $OUT/summary.txt
cat $OUT/summary.txt; grep -i "error\|EXP_" $OUT/log.txt | sort | uniq -c | head -8
