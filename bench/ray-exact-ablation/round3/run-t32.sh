#!/bin/bash
# The pyramid as a texture: R8Uint mips (tex) or R32Uint texels of 2x2 tiles (tex32, what a WebGPU storage build could write), against the shipped buffer (none).
for f in .gl/*.deb; do dpkg -x $f /; done; ldconfig
gunzip -c devexp/strata.gz > /tmp/strata; chmod +x /tmp/strata
export STRATA_CACHE_DIR=/tmp/strata-cache
S=/tmp/strata
V="none tex tex32 none2 tex2 tex322 4k-none 4k-tex 4k-tex32"
for v in $V; do
  k=${v#4k-}; k=${k%2}; [ $k = tex3 ] && k=tex32
  case $k in
    none) E="STRATA_SHADER_SED_FILE=devexp/none.txt" ;;
    tex) E="STRATA_EXP_PYRAMID=tex STRATA_SHADER_SED_FILE=devexp/piptex.txt" ;;
    tex32) E="STRATA_EXP_PYRAMID=tex32 STRATA_SHADER_SED_FILE=devexp/piptex32.txt" ;;
  esac
  A=""; case $v in 4k-*) A="--size 3840x2160";; esac
  env $E timeout 100 $S compare --frames 20 $A --methods ray-exact --no-edits --out /tmp/$v >> $OUT/log.txt 2>&1
done
python3 devexp/summarise.py $V > $OUT/summary.txt
cat $OUT/summary.txt; grep -i "error\|EXP_" $OUT/log.txt | sort | uniq -c | head -8
