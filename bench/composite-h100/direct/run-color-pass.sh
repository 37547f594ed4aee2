#!/bin/bash
# What render_into adds after 90378fb (a colour-only pass after depth drawn into the caller's Depth32Float): per method and target pair, 1280x800 and 4K.
for f in .gl/*.deb; do dpkg -x $f /; done; ldconfig
gunzip -c devexp/composite_cost.gz > /tmp/cc; chmod +x /tmp/cc
for s in 1280x800 3840x2160; do
  for m in ray mesh ray-exact; do
    echo "== $m $s" >> $OUT/composite.txt
    timeout 120 /tmp/cc --method $m --size $s --frames 200 >> $OUT/composite.txt 2>&1
  done
done
grep -E "^==|Bgra8UnormSrgb|Rgba16Float \+ Depth32Float" $OUT/composite.txt | cut -c1-260
