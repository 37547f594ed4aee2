#!/bin/bash
# 16x16 workgroups (launch count / 4) for the shading pass, and for the march with the beam off (the beam's wide search is per 8x8 workgroup).
for f in .gl/*.deb; do dpkg -x $f /; done; ldconfig
gunzip -c devexp/strata.gz > /tmp/strata; chmod +x /tmp/strata
export STRATA_CACHE_DIR=/tmp/strata-cache
S=/tmp/strata
V="none wgshade nobeam nobeamwg none2 wgshade2 nobeam2 nobeamwg2"
for v in $V; do
  case ${v%2} in
    none) E="STRATA_SHADER_SED_FILE=devexp/none.txt" ;;
    wgshade) E="STRATA_EXP_WG16=shade STRATA_SHADER_SED_FILE=devexp/wgshade.txt" ;;
    nobeam) E="STRATA_EXACT_BEAM=off STRATA_SHADER_SED_FILE=devexp/none.txt" ;;
    nobeamwg) E="STRATA_EXACT_BEAM=off STRATA_EXP_WG16=shade,march STRATA_SHADER_SED_FILE=devexp/wgboth.txt" ;;
  esac
  env $E timeout 100 $S compare --frames 20 --methods ray-exact --no-edits --out /tmp/$v >> $OUT/log.txt 2>&1
done
python3 devexp/summarise.py $V > $OUT/summary.txt
cat $OUT/summary.txt; grep -i "error\|panic" $OUT/log.txt | sort | uniq -c | head -8
