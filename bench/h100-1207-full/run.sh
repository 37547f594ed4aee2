#!/bin/bash
# One H100 call: the full default protocol (every method, twelve views,
# 1280x800, shadows, the crater edit) with `devbin/strata.xz`. Carry `.gl`
# and `devbin`.   OUT=$OUT bash bench/h100-1207-full/run.sh
for f in .gl/*.deb; do dpkg -x $f /; done; ldconfig
python3 -c 'import lzma, sys; sys.stdout.buffer.write(lzma.open(sys.argv[1]).read())' devbin/strata.xz > /tmp/strata
chmod +x /tmp/strata
export STRATA_CACHE_DIR=/tmp/strata-cache
/tmp/strata --version > $OUT/log.txt
start=$(date +%s)
timeout 540 /tmp/strata compare --out /tmp/full >> $OUT/log.txt 2>&1
echo "compare rc $? in $(( $(date +%s) - start )) s" >> $OUT/log.txt
cp /tmp/full/report.md $OUT/; cp /tmp/full/results-*.json $OUT/
tail -3 $OUT/log.txt
