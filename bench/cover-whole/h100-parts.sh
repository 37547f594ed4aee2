#!/usr/bin/env bash
# One H100 call: what the one-pass march (`cs_ray_exact`, the covered
# frame) spends its registers and time on. `devhook/` holds a scratch build
# (not committed) of this tree plus the shader-rewrite hook
# (`bench/ray-exact-ablation/round2/shader-sed-hook.patch`, also in
# `pipeline_stats`), and the rule files `devhook/sed/*.txt` (diagnostics:
# pictures change). Per rule: the driver's register count, then two timed
# protocol runs (the moving camera is `h100-chain.sh`'s). Carry `.gl` and `devhook`.   OUT=$OUT bash this
set -u
for f in .gl/*.deb; do dpkg -x "$f" /; done; ldconfig
python3 -c 'import lzma, sys; sys.stdout.buffer.write(lzma.open(sys.argv[1]).read())' devhook/strata.xz > /tmp/strata
chmod +x /tmp/strata
C="EXACT_CLIMB=1,EXACT_LOG_RATIO=2,EXACT_START_LEVEL=6,EXACT_FUSED_DESCENT=0,EXACT_ITERATION_STATS=0,EXACT_CAVE_SKIP=1,EXACT_TEXEL_BLOCKS=0,EXACT_BEAM=1,EXACT_BEAM_SEARCH=1,EXACT_SHADOW_ROUNDS=8,EXACT_BEAM_LEVEL=2,EXACT_BEAM_TEXELS=1"
RULES=${RULES:-none seqnormal seqtaps seqboth noshade notaps flatnormal}
for r in $RULES; do
    echo "== $r cs_ray_exact"
    STRATA_SHADER_SED_FILE=devhook/sed/$r.txt devhook/pipeline_stats ray_exact.wgsl cs_ray_exact "$C" 2>&1 | grep -E "Register|Shared|MISS"
done | tee "$OUT/stats.txt"
echo "== deferred march" >> "$OUT/stats.txt"
devhook/pipeline_stats ray_exact_deferred.wgsl cs_exact_march_hits "$C" 2>&1 | grep -E "Register" >> "$OUT/stats.txt"
W=$(mktemp -d); export STRATA_CACHE_DIR=$W/cache
/tmp/strata generate --out "$W/world" > /dev/null
for k in 1 2; do
    for r in $RULES; do
        STRATA_SHADER_SED_FILE=devhook/sed/$r.txt timeout 150 /tmp/strata compare --level "$W/world" --frames 20 --no-edits \
            --methods ray-exact --out "$W/$r-$k" > "$W/$r-$k.log" 2>&1 || echo "$r failed: $(tail -2 "$W/$r-$k.log")"
    done
done
python3 bench/issue36-loop-bounding/summary_all.py $(for r in $RULES; do echo "$W/$r-1/ $W/$r-2/"; done) | tee "$OUT/summary.txt"
. bench/cover-whole/lib.sh
collect_runs
