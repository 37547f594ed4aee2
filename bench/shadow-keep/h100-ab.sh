#!/usr/bin/env bash
# One H100 call: `ray-exact` keeping the shadow blocks of earlier frames
# (`devbin/strata-keep.xz`) against the baseline that casts every block it
# reads each frame (`devbin/strata.xz`, c4fa74d) and against itself with
# STRATA_EXACT_KEEP=off, alternated in separate processes, REPS (3) runs
# each: the protocol's twelve views, 1280x800,
# shadows, 20 frames. Then the moving camera: `compare --gameplay` along the
# video's path (600 frames, 64 edits a frame, and the same path without
# edits: "frame alone"), both binaries. Carry `.gl` and `devbin`.
#   OUT=$OUT [REPS=3] bash bench/shadow-keep/h100-ab.sh
set -u
for f in .gl/*.deb; do dpkg -x "$f" /; done; ldconfig
for b in strata strata-keep; do
    python3 -c 'import lzma, sys; sys.stdout.buffer.write(lzma.open(sys.argv[1]).read())' devbin/$b.xz > /tmp/$b
    chmod +x /tmp/$b
done
nvidia-smi --query-gpu=name,driver_version --format=csv,noheader | tee "$OUT/gpu.txt"
W=$(mktemp -d); export STRATA_CACHE_DIR=$W/cache
/tmp/strata generate --out "$W/world" > /dev/null
run() {
    env $3 timeout 150 "/tmp/$2" compare --level "$W/world" --frames 20 --no-edits \
        --methods ray-exact --out "$W/$1" > "$W/$1.log" 2>&1 || echo "$1 failed: $(tail -2 "$W/$1.log")"
}
for k in $(seq 1 "${REPS:-3}"); do
    run base-$k strata X=1
    run keep-$k strata-keep X=1
    [ "$k" -le "${OFF_REPS:-9}" ] && run keepoff-$k strata-keep STRATA_EXACT_KEEP=off
done
python3 bench/issue36-loop-bounding/summary_all.py "$W"/base-*/ "$W"/keep-*/ "$W"/keepoff-*/ | tee "$OUT/summary.txt"
for b in strata strata-keep; do
    timeout 150 "/tmp/$b" compare --level "$W/world" --gameplay --view-names hangar --no-edits \
        --methods ray-exact --out "$W/gameplay-$b" > "$OUT/gameplay-$b.log" 2>&1 \
        || echo "gameplay $b failed: $(tail -2 "$OUT/gameplay-$b.log")"
done
mkdir -p "$OUT/runs"
for d in "$W"/*/; do
    n=$(basename "$d"); case $n in world|cache) continue ;; esac
    for f in "$d"/*.json; do [ -e "$f" ] && cp "$f" "$OUT/runs/$n-$(basename "$f")"; done
done
(cd "$OUT" && tar czf runs.tgz runs && rm -rf runs)
