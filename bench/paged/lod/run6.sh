#!/bin/bash
# Device run 6: level of detail for horizon views (issue 33). The 65536^2
# store with its levels of detail; horizon flights with and without LOD; the
# twelve views at far 16384 against the CPU reference at the same far plane.
for f in .gl/*.deb; do dpkg -x $f /; done; ldconfig
S=./devbin/strata
export STRATA_CACHE_DIR=/tmp/strata-cache
W=/tmp/fs/world-65536x65536
$S --version > $OUT/version.txt
[ -f $W/zarr.json ] || ( /usr/bin/time -v $S generate --size 65536x65536 --to store --out $W ) > $OUT/gen65k.txt 2>&1
du -sb $W $W/lod >> $OUT/gen65k.txt
$S info --level $W >> $OUT/gen65k.txt 2>&1
# Horizon flights, far 16384: the views' path; the same at altitude 300 looking 6 degrees down; both without LOD.
for mode in "views:" "alt:--altitude 300 --pitch -6"; do
  name=${mode%%:*}; extra=${mode#*:}
  $S fly --level $W --far 16384 --frames 300 $extra --out /tmp/fly-$name > $OUT/fly-$name.txt 2>&1
  $S fly --level $W --far 16384 --frames 300 $extra --lod-pixels 0 --out /tmp/fly-$name-nolod > $OUT/fly-$name-nolod.txt 2>&1
done
tar czf $OUT/fly.tgz -C /tmp fly-views fly-alt fly-views-nolod fly-alt-nolod 2>/dev/null
ls -la $OUT
