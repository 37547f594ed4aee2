#!/bin/bash
# Measure `strata generate --to store` at three sizes (release build).
S=/work/wt-gen/target/release/strata
cd /tmp/sgen
for size in 16384x16384 32768x32768 65536x65536; do
  out=/tmp/sgen/store-$size
  rm -rf $out
  echo "=== $size  start $(date -u +%H:%M:%S)  $(cat /proc/loadavg)" 
  /usr/bin/time -v $S generate --out $out --size $size --to store > gen-$size.out 2> gen-$size.err
  echo "rc $?  end $(date -u +%H:%M:%S)  $(cat /proc/loadavg)"
  grep -E "Elapsed|User time|System time|Maximum resident|Percent of CPU" gen-$size.err
  head -2 gen-$size.out
  echo "apparent $(du -sb $out | cut -f1)  allocated $(du -s --block-size=1 $out | cut -f1)  files $(find $out -type f | wc -l)"
  if [ $size != 65536x65536 ]; then rm -rf $out; fi
done
