#!/bin/bash
# What render_into adds after the direct roads (76f9f8d): per method and target pair, 1280x800 and 4K.
for f in .gl/*.deb; do dpkg -x $f /; done; ldconfig
gunzip -c devexp/composite_cost.gz (a stripped release build of examples/composite_cost.rs at 76f9f8d) > /tmp/cc; chmod +x /tmp/cc
for s in 1280x800 3840x2160; do
  for m in ray-exact mesh ray voxel-compute; do
    echo "== $m $s" >> $OUT/composite.txt
    timeout 120 /tmp/cc --method $m --size $s --frames 200 >> $OUT/composite.txt 2>&1
  done
  echo "== ray-exact $s --shadows" >> $OUT/composite.txt
  timeout 120 /tmp/cc --method ray-exact --size $s --frames 200 --shadows >> $OUT/composite.txt 2>&1
done
grep -E "^==|adapter|Rgba8Unorm \+ Depth32Float x1 \(TextureUsages\(COPY_DST \| STORAGE|Rgba8Unorm \+ Depth32Float x1 \(TextureUsages\(RENDER_ATTACHMENT\)" $OUT/composite.txt | cut -c1-400
