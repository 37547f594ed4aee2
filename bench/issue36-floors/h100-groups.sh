#!/usr/bin/env bash
# One H100 call: does a bigger workgroup lower the per-pass floor? The
# experiment build (`devexp2`: the shade pass in 8x8, 16x16 or 32x8
# workgroups by STRATA_EXP_SHADE; with the beam off, the march in 16x16 by
# STRATA_EXP_MARCH16; plus the shader-rewrite hook). Carry `.gl`, `devexp2`.
set -u
for f in .gl/*.deb; do dpkg -x "$f" /; done; ldconfig
gunzip -c devexp2/strata.gz > /tmp/strata-exp; chmod +x /tmp/strata-exp
W=$(mktemp -d); export STRATA_CACHE_DIR=$W/cache
/tmp/strata-exp generate --out "$W/world" > /dev/null
S=bench/issue36-floors/sed
run() {
    local name=$1; shift 1
    env "$@" timeout 120 /tmp/strata-exp compare --level "$W/world" --frames 20 --no-edits --methods ray-exact \
        --out "$W/$name" > "$W/$name.log" 2>&1 || echo "$name failed: $(tail -2 "$W/$name.log")"
}
run base-1
run shade16 STRATA_EXP_SHADE=16
run shade32x8 STRATA_EXP_SHADE=32x8
run nostats-shade16 STRATA_EXP_SHADE=16 STRATA_SHADER_SED_FILE=$S/nostats.txt
run nobeam STRATA_EXACT_BEAM=off
run nobeam-march16 STRATA_EXACT_BEAM=off STRATA_EXP_MARCH16=1
run floor STRATA_SHADER_SED_FILE=$S/cap0nostats.txt STRATA_EXACT_BEAM=off
run floor-16 STRATA_SHADER_SED_FILE=$S/cap0nostats.txt STRATA_EXACT_BEAM=off STRATA_EXP_MARCH16=1 STRATA_EXP_SHADE=16
run shadesky-16 STRATA_SHADER_SED_FILE=$S/shadesky.txt STRATA_EXP_SHADE=16
run base-2
python3 bench/issue36-loop-bounding/summary_all.py "$W"/base-1 "$W"/base-2 "$W"/shade16 "$W"/shade32x8 \
    "$W"/nostats-shade16 "$W"/nobeam "$W"/nobeam-march16 "$W"/floor "$W"/floor-16 "$W"/shadesky-16 \
    | tee "$OUT/summary.txt"
mkdir -p "$OUT/runs"
for d in "$W"/*/; do
    n=$(basename "$d"); case $n in world|cache) continue ;; esac
    cp "$d"/results-*.json "$OUT/runs/$n.json"
done
(cd "$OUT" && tar czf runs.tgz runs && rm -rf runs)
