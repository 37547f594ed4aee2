#!/usr/bin/env bash
# One H100 call: the driver's statistics of ray-exact's compute pipelines
# (`crates/render/examples/pipeline_stats.rs`, built stripped into
# `devstats/`), with the shipped pipeline constants (`bindings.rs`) and a few
# variants. Carry `.gl`, `devstats`.   OUT=$OUT bash this
set -u
for f in .gl/*.deb; do dpkg -x "$f" /; done; ldconfig
P=devstats/pipeline_stats
CORE="EXACT_CLIMB=1,EXACT_LOG_RATIO=2,EXACT_START_LEVEL=6,EXACT_FUSED_DESCENT=0,EXACT_ITERATION_STATS=0"
BEAM="EXACT_BEAM=1,EXACT_BEAM_SEARCH=1,EXACT_SHADOW_ROUNDS=8,EXACT_BEAM_LEVEL=2,EXACT_BEAM_TEXELS=1"
stat() {
    echo "== $*"
    "$P" "$@" 2>&1
}
{
stat ray_exact_deferred.wgsl cs_exact_march_hits "$CORE,EXACT_CAVE_SKIP=1,$BEAM"
stat ray_exact_deferred.wgsl cs_exact_march_hits "$CORE,EXACT_CAVE_SKIP=1,$BEAM,EXACT_BEAM=0"
stat ray_exact_deferred.wgsl cs_exact_march_hits "$CORE,EXACT_CAVE_SKIP=1,$BEAM,EXACT_BEAM_SEARCH=2"
stat ray_exact_deferred.wgsl cs_exact_march_hits "$CORE,EXACT_CAVE_SKIP=0,$BEAM,EXACT_BEAM_TEXELS=0"
stat ray_exact_deferred.wgsl cs_exact_march_hits "$CORE,EXACT_CAVE_SKIP=1,$BEAM,EXACT_FUSED_DESCENT=1"
stat ray_exact_deferred.wgsl cs_exact_march_hits "$CORE,EXACT_CAVE_SKIP=1,$BEAM,EXACT_ITERATION_STATS=1"
stat ray_exact_beam.wgsl cs_exact_beam_wide "$CORE,EXACT_CAVE_SKIP=1,$BEAM,EXACT_BEAM_SEARCH=2"
stat ray_exact_shadow.wgsl cs_exact_shadow_blocks "$CORE,EXACT_CAVE_SKIP=0,$BEAM"
stat ray_exact_deferred.wgsl cs_exact_shade "$CORE,EXACT_CAVE_SKIP=1,$BEAM"
stat ray_exact.wgsl cs_ray_exact "$CORE,EXACT_CAVE_SKIP=1,$BEAM"
} | tee "$OUT/stats.txt"
