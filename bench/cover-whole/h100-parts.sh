#!/usr/bin/env bash
# One H100 call: what the one-pass march (`cs_ray_exact`, the covered
# frame) spends its registers and time on. `devhook/` holds a scratch build
# (not committed) of this tree plus the shader-rewrite hook
# (`bench/ray-exact-ablation/round2/shader-sed-hook.patch`, and
# `pipeline-stats-sed-hook.patch` for `pipeline_stats`); without
# STRATA_SHADER_SED_FILE it is this tree's binary. Rules (`sed/*.txt`):
# `none` the shipped shader; `chain` none with STRATA_EXACT_SHADE_CHAIN=on
# (same pictures); `sellevels` the pyramid levels' table read at constant
# indices 0-8 and picked by `select` (same pictures where every visited
# level is even, as with EXACT_LOG_RATIO 2), not at a lane's own index; the rest are diagnostics whose pictures change
# (`noshade` no shading at all, `notaps` no shadow taps, `flatnormal` no
# normal fetches, `nopalette` no palette read, `noranges` no ramp read,
# `nodepth` no depth store, `nomarch` the beam and the stores only: every pixel sky). Per rule: the driver's register count, then
# REPS timed protocol runs; then the moving camera, cover on and off, and
# with edits, edit keep on and off.
# Carry `.gl` and `devhook`.   OUT=$OUT [REPS=2] [GAMEPLAY=1] bash this
set -u
for f in .gl/*.deb; do dpkg -x "$f" /; done; ldconfig
python3 -c 'import lzma, sys; sys.stdout.buffer.write(lzma.open(sys.argv[1]).read())' devhook/strata.xz > /tmp/strata
chmod +x /tmp/strata
nvidia-smi --query-gpu=name,driver_version --format=csv,noheader | tee "$OUT/gpu.txt"
S=bench/cover-whole/sed
C="EXACT_CLIMB=1,EXACT_LOG_RATIO=2,EXACT_START_LEVEL=6,EXACT_FUSED_DESCENT=0,EXACT_ITERATION_STATS=0,EXACT_CAVE_SKIP=1,EXACT_TEXEL_BLOCKS=0,EXACT_BEAM=1,EXACT_BEAM_SEARCH=1,EXACT_SHADOW_ROUNDS=8,EXACT_BEAM_LEVEL=2,EXACT_BEAM_TEXELS=1"
RULES=${RULES:-none chain sellevels noshade notaps flatnormal nopalette noranges nodepth nomarch}
rule_file() { [ "$1" = chain ] && echo $S/none.txt || echo $S/$1.txt; }
rule_env() { [ "$1" = chain ] && echo STRATA_EXACT_SHADE_CHAIN=on || echo X=1; }
for r in $RULES; do
    chain=$([ "$r" = chain ] && echo 1 || echo 0)
    echo "== $r cs_ray_exact"
    STRATA_SHADER_SED_FILE=$(rule_file $r) devhook/pipeline_stats ray_exact.wgsl cs_ray_exact "$C,SHADE_FETCH_CHAIN=$chain" 2>&1 | grep -E "Register|Shared|MISS|rror"
done | tee "$OUT/stats.txt"
for chain in 0 1; do
    echo "== deferred march / shade SHADE_FETCH_CHAIN=$chain"
    for e in cs_exact_march_hits cs_exact_shade; do
        devhook/pipeline_stats ray_exact_deferred.wgsl $e "$C,SHADE_FETCH_CHAIN=$chain" 2>&1 | grep -E "Register|rror"
    done
done | tee -a "$OUT/stats.txt"
W=$(mktemp -d); export STRATA_CACHE_DIR=$W/cache
/tmp/strata generate --out "$W/world" > /dev/null
for k in $(seq 1 "${REPS:-2}"); do
    for r in $RULES; do
        env $(rule_env $r) STRATA_SHADER_SED_FILE=$(rule_file $r) timeout 150 /tmp/strata compare --level "$W/world" --frames 20 --no-edits \
            --methods ray-exact --out "$W/$r-$k" > "$W/$r-$k.log" 2>&1 || echo "$r failed: $(tail -2 "$W/$r-$k.log")"
    done
done
python3 bench/issue36-loop-bounding/summary_all.py $(for r in $RULES; do for k in $(seq 1 "${REPS:-2}"); do echo "$W/$r-$k/"; done; done) | tee "$OUT/summary.txt"
. bench/cover-whole/lib.sh
[ "${GAMEPLAY:-1}" = 1 ] && gameplay_on_off
# The moving camera with edits: an edit spoils only the blocks it reaches
# (the default) or every kept block (STRATA_EXACT_EDIT_KEEP=off, as before
# `fe6462f`; `bench/edit-keep/`), twice each.
if [ "${GAMEPLAY:-1}" = 1 ]; then
    for k in 1 2; do
        gameplay_run /tmp/strata editkeep-on-$k X=1
        gameplay_run /tmp/strata editkeep-off-$k STRATA_EXACT_EDIT_KEEP=off
    done
fi
collect_runs
