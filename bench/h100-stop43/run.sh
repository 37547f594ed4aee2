#!/bin/bash
# Device run 55 (H100): the full default protocol (every method, twelve views, 1280x800, the crater edit) at HEAD.
for f in .gl/*.deb; do dpkg -x $f /; done; ldconfig
gunzip -c devbin/strata-head.gz > /tmp/strata; chmod +x /tmp/strata
export STRATA_CACHE_DIR=/tmp/strata-cache
/tmp/strata --version > $OUT/log.txt
start=$(date +%s)
timeout 520 /tmp/strata compare --out /tmp/full >> $OUT/log.txt 2>&1
echo "compare rc $? in $(( $(date +%s) - start )) s" >> $OUT/log.txt
cp /tmp/full/report.md $OUT/; cp /tmp/full/results-*.json $OUT/
tail -3 $OUT/log.txt
