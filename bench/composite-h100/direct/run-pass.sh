#!/bin/bash
# What render_into adds after ec0e473 (the full-screen pass reads a compute method's depth image): per method and target pair, 1280x800 and 4K.
for f in .gl/*.deb; do dpkg -x $f /; done; ldconfig
gunzip -c devexp/composite_cost.gz > /tmp/cc; chmod +x /tmp/cc
for s in 1280x800 3840x2160; do
  for m in ray-exact voxel-compute mesh ray; do
    echo "== $m $s" >> $OUT/composite.txt
    timeout 120 /tmp/cc --method $m --size $s --frames 200 >> $OUT/composite.txt 2>&1
  done
done
grep -E "^==|Rgba8Unorm \+ Depth32Float x1 \(TextureUsages\(COPY_DST \| STORAGE|x1 \(TextureUsages\(RENDER_ATTACHMENT\)" $OUT/composite.txt | cut -c1-300
