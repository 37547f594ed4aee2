#!/bin/bash
# One H100 call: the full default protocol (every method, twelve views,
# 1280x800, shadows, the crater edit) with `devbin/strata-keep.xz` (the
# lattice fit and kept shadow blocks). Carry `.gl` and `devbin`.
#   OUT=$OUT bash bench/shadow-keep/full.sh
for f in .gl/*.deb; do dpkg -x $f /; done; ldconfig
python3 -c 'import lzma, sys; sys.stdout.buffer.write(lzma.open(sys.argv[1]).read())' devbin/strata-keep.xz > /tmp/strata
chmod +x /tmp/strata
export STRATA_CACHE_DIR=/tmp/strata-cache
/tmp/strata --version > $OUT/log.txt
start=$(date +%s)
timeout 400 /tmp/strata compare --out /tmp/full >> $OUT/log.txt 2>&1
echo "compare rc $? in $(( $(date +%s) - start )) s" >> $OUT/log.txt
cp /tmp/full/report.md $OUT/; cp /tmp/full/results-*.json $OUT/
tail -3 $OUT/log.txt
