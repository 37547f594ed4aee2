#!/usr/bin/env bash
# One H100 call: `ray-exact` with the view's cover cast ahead and still
# frames marched in one pass (`devbin/strata-cover.xz`, default) against
# the same binary with STRATA_EXACT_COVER=off (the deferred frame every
# frame, as main before this change) and the previous main's binary
# (`devbin/strata-keep.xz`, 6c4db5f), alternated in separate processes,
# REPS (2) runs each: the protocol's twelve views, 1280x800, shadows, 20
# frames. Then the moving camera (`compare --gameplay --no-edits` along
# the video's path, the frame alone), cover on and off. Carry `.gl` and
# `devbin`.
#   OUT=$OUT [REPS=2] bash bench/cover-whole/h100-ab.sh
set -u
for f in .gl/*.deb; do dpkg -x "$f" /; done; ldconfig
for b in strata-cover strata-keep; do
    python3 -c 'import lzma, sys; sys.stdout.buffer.write(lzma.open(sys.argv[1]).read())' devbin/$b.xz > /tmp/$b
    chmod +x /tmp/$b
done
nvidia-smi --query-gpu=name,driver_version --format=csv,noheader | tee "$OUT/gpu.txt"
W=$(mktemp -d); export STRATA_CACHE_DIR=$W/cache
/tmp/strata-cover generate --out "$W/world" > /dev/null
run() {
    env $3 timeout 150 "/tmp/$2" compare --level "$W/world" --frames 20 --no-edits \
        --methods ray-exact --out "$W/$1" > "$W/$1.log" 2>&1 || echo "$1 failed: $(tail -2 "$W/$1.log")"
}
for k in $(seq 1 "${REPS:-2}"); do
    run cover-$k strata-cover X=1
    run off-$k strata-cover STRATA_EXACT_COVER=off
    run prev-$k strata-keep X=1
done
python3 bench/issue36-loop-bounding/summary_all.py "$W"/cover-*/ "$W"/off-*/ "$W"/prev-*/ | tee "$OUT/summary.txt"
for v in on off; do
    env STRATA_EXACT_COVER=$([ $v = on ] && echo 256 || echo off) timeout 150 /tmp/strata-cover compare \
        --level "$W/world" --gameplay --view-names hangar --no-edits \
        --methods ray-exact --out "$W/gameplay-$v" > "$OUT/gameplay-$v.log" 2>&1 \
        || echo "gameplay $v failed: $(tail -2 "$OUT/gameplay-$v.log")"
done
mkdir -p "$OUT/runs"
for d in "$W"/*/; do
    n=$(basename "$d"); case $n in world|cache) continue ;; esac
    for f in "$d"/*.json; do [ -e "$f" ] && cp "$f" "$OUT/runs/$n-$(basename "$f")"; done
done
(cd "$OUT" && tar czf runs.tgz runs && rm -rf runs)
