#!/usr/bin/env bash
# One H100 call: the covered frame's one-pass march (`cs_ray_exact`) with
# the shading's fetches chained (STRATA_EXACT_SHADE_CHAIN=on,
# `SHADE_FETCH_CHAIN` in `shading.wgsl`; the same pictures) against the
# default, and the cover off; the driver's register counts of the
# pipelines that shade; the moving camera with the still-view rule.
# `devbin/strata-cover.xz` and `devbin/pipeline_stats` are this tree's
# release builds. Carry `.gl` and `devbin`.
#   OUT=$OUT [REPS=2] [OFF=1] [GAMEPLAY=1] bash this
set -u
for f in .gl/*.deb; do dpkg -x "$f" /; done; ldconfig
python3 -c 'import lzma, sys; sys.stdout.buffer.write(lzma.open(sys.argv[1]).read())' devbin/strata-cover.xz > /tmp/strata
chmod +x /tmp/strata
nvidia-smi --query-gpu=name,driver_version --format=csv,noheader | tee "$OUT/gpu.txt"
C="EXACT_CLIMB=1,EXACT_LOG_RATIO=2,EXACT_START_LEVEL=6,EXACT_FUSED_DESCENT=0,EXACT_ITERATION_STATS=0,EXACT_CAVE_SKIP=1,EXACT_TEXEL_BLOCKS=0,EXACT_BEAM=1,EXACT_BEAM_SEARCH=1,EXACT_SHADOW_ROUNDS=8,EXACT_BEAM_LEVEL=2,EXACT_BEAM_TEXELS=1"
for chain in 0 1; do
    for e in "ray_exact.wgsl cs_ray_exact" "ray_exact_deferred.wgsl cs_exact_march_hits" "ray_exact_deferred.wgsl cs_exact_shade"; do
        echo "== $e SHADE_FETCH_CHAIN=$chain"
        devbin/pipeline_stats $e "$C,SHADE_FETCH_CHAIN=$chain" 2>&1 | grep -E "Register|rror"
    done
done | tee "$OUT/stats.txt"
W=$(mktemp -d); export STRATA_CACHE_DIR=$W/cache
/tmp/strata generate --out "$W/world" > /dev/null
run() {
    env $2 timeout 150 /tmp/strata compare --level "$W/world" --frames 20 --no-edits \
        --methods ray-exact --out "$W/$1" > "$W/$1.log" 2>&1 || echo "$1 failed: $(tail -2 "$W/$1.log")"
}
for k in $(seq 1 "${REPS:-2}"); do
    run cover-$k X=1
    run chain-$k STRATA_EXACT_SHADE_CHAIN=on
    [ "${OFF:-1}" = 1 ] && run off-$k STRATA_EXACT_COVER=off
done
python3 bench/issue36-loop-bounding/summary_all.py "$W"/*-[0-9]/ | tee "$OUT/summary.txt"
. bench/cover-whole/lib.sh
[ "${GAMEPLAY:-1}" = 1 ] && gameplay_on_off
collect_runs
