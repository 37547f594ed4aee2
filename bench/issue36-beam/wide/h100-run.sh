#!/bin/bash
# For the device (not yet run): ray-exact's beam searches A/B in one binary, the
# protocol's 12 views at 1280x800 with shadows, 20 frames, twice alternated, and
# --no-shadows once. Expects the `beam` branch's release binary gzipped as
# devbin/strata.gz and the GL/Vulkan loaders' .debs in .gl/ (the device recipe).
for f in .gl/*.deb; do dpkg -x $f /; done; ldconfig
gunzip -c devbin/strata.gz > /tmp/strata; chmod +x /tmp/strata
export STRATA_CACHE_DIR=/tmp/strata-cache
C="compare --methods ray-exact --no-edits --frames 20"
for i in 1 2; do
  for b in off serial wide wide-pass; do
    STRATA_EXACT_BEAM=$b /tmp/strata $C --out /tmp/r-$b-$i >> $OUT/log.txt 2>&1
    cp /tmp/r-$b-$i/results-*.json /tmp/res-$b-$i.json
  done
done
# The shadow blocks' wide search cut to one round (the serial search's):
# the shadow pass is one wave, its time the longest chain of dependent steps.
for i in 1 2; do
  STRATA_EXACT_SHADOW_ROUNDS=1 /tmp/strata $C --out /tmp/s1-$i >> $OUT/log.txt 2>&1
  cp /tmp/s1-$i/results-*.json /tmp/res-wide-pass-shadow1-$i.json
done
for b in serial wide wide-pass; do
  STRATA_EXACT_BEAM=$b /tmp/strata $C --no-shadows --out /tmp/n-$b >> $OUT/log.txt 2>&1
  cp /tmp/n-$b/results-*.json /tmp/res-noshadows-$b.json
done
python3 bench/issue36-beam/wide/summary.py /tmp/res-*.json > $OUT/summary.txt 2>&1
tar czf $OUT/results.tgz -C /tmp $(cd /tmp && ls res-*.json)
/tmp/strata --version >> $OUT/log.txt
