#!/bin/bash
# Device run 54 (H100): the gameplay workload for sliced after eb94930 (the beam's pyramid updated every frame).
for f in .gl/*.deb; do dpkg -x $f /; done; ldconfig
gunzip -c devbin/strata-rows.gz > devbin/strata; chmod +x devbin/strata
export STRATA_CACHE_DIR=/tmp/strata-cache
timeout 300 devbin/strata compare --gameplay --methods sliced:512,sliced:512/refine,sliced:512/fragwalk --view-names hangar --frames 20 --out /tmp/gp > $OUT/log.txt 2>&1
echo "gameplay rc $?" >> $OUT/log.txt
sed -n '/Gameplay/,/## Figures/p' /tmp/gp/report.md > $OUT/gameplay.md
cp /tmp/gp/results-*.json $OUT/results-gameplay.json
cat $OUT/gameplay.md
