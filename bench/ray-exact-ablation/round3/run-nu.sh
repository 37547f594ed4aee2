#!/bin/bash
# Experiment: the pyramid read without a per-lane index into the uniform level table (texnu: R8Uint mip texture; rownu: the shipped buffer).
for f in .gl/*.deb; do dpkg -x $f /; done; ldconfig
gunzip -c devexp/strata.gz > /tmp/strata; chmod +x /tmp/strata
export STRATA_CACHE_DIR=/tmp/strata-cache
S=/tmp/strata
V="none tex texnu rownu none2 texnu2 rownu2"
for v in $V; do
  k=${v%2}
  case $k in
    none) E="STRATA_SHADER_SED_FILE=devexp/none.txt" ;;
    tex) E="STRATA_EXP_PYRAMID=tex STRATA_SHADER_SED_FILE=devexp/piptex.txt" ;;
    topstex) E="STRATA_EXP_TOPSTEX=1 STRATA_SHADER_SED_FILE=devexp/topstex.txt" ;;
    texnu) E="STRATA_EXP_PYRAMID=tex STRATA_SHADER_SED_FILE=devexp/piptexnu.txt" ;;
    rownu) E="STRATA_SHADER_SED_FILE=devexp/rownu.txt" ;;
  esac
  env $E timeout 100 $S compare --frames 20 --methods ray-exact --no-edits --out /tmp/$v >> $OUT/log.txt 2>&1
done
python3 devexp/summarise.py $V > $OUT/summary.txt
cat $OUT/summary.txt; grep -i "error\|EXP_" $OUT/log.txt | sort | uniq -c | head -8
