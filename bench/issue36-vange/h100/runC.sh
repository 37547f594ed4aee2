#!/bin/bash
# Device call C: scattered beside vange-rs at the same density (Strata's default 4 = vange-rs 4,4,4).
for f in .gl/*.deb; do dpkg -x $f /; done; ldconfig
gunzip -c devbin/strata.gz > devbin/strata; chmod +x devbin/strata; gunzip -f devbin-vange/level.gz; chmod +x devbin-vange/level
OUTC=$OUT
OUT=$OUTC/side-scattered STRATA_METHODS=scattered,scattered:2 VANGE_TERRAINS="scattered=Scattered,--scatter-density,4,4,4 scattered:2=Scattered,--scatter-density,2,2,2" VANGE_WARMUP=10 timeout 300 bash bench/issue36-vange/run.sh > $OUTC/side-scattered.log 2>&1
cat $OUTC/side-scattered/table.md
