#!/bin/bash
# Device run 31: compare --gameplay (K = 64, 600 frames on the video's path) for mesh, ray-exact and voxel-compute at 1280x800:
# the previous binary (08330a0: mesh refits on the frame) against the merged one (mesh refits off the frame; ray-exact's beam pre-pass).
for f in .gl/*.deb; do dpkg -x $f /; done; ldconfig
mkdir -p /tmp/bin; for f in devbin/strata*.gz; do gunzip -c $f > /tmp/bin/$(basename $f .gz); chmod +x /tmp/bin/$(basename $f .gz); done
export STRATA_CACHE_DIR=/tmp/strata-cache
C="compare --gameplay --view-names hangar --no-edits --methods mesh,ray-exact,voxel-compute"
for b in strata-old strata; do
  ( time timeout 280 /tmp/bin/$b $C --out /tmp/g-$b ) >> $OUT/log.txt 2>&1
  cp /tmp/g-$b/results-*.json $OUT/gameplay-$b.json; cp /tmp/g-$b/report.md $OUT/report-$b.md
done
/tmp/bin/strata --version >> $OUT/log.txt; /tmp/bin/strata-old --version >> $OUT/log.txt
