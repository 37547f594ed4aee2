#!/bin/bash
# lavapipe (this 2-core machine), 640x400, the twelve views, 5 frames, no
# edits: the baseline c4fa74d (/tmp/strata-old, from devbin/strata.xz)
# against this build with kept blocks (default) and with STRATA_EXACT_KEEP=off,
# alternated, twice. World in /tmp/w (`strata generate --out /tmp/w`).
cd /work/main
for k in 1 2; do
  timeout 900 /tmp/strata-old compare --level /tmp/w --size 640x400 --frames 5 --no-edits --methods ray-exact --out /tmp/lq-old-$k > /tmp/lq-old-$k.log 2>&1 || echo "fail old $k"
  for v in on off; do
    STRATA_EXACT_KEEP=$v timeout 900 ./target/release/strata compare --level /tmp/w --size 640x400 --frames 5 --no-edits --methods ray-exact --out /tmp/lq-$v-$k > /tmp/lq-$v-$k.log 2>&1 || echo "fail $v $k"
  done
done
echo done > /tmp/lq-done
