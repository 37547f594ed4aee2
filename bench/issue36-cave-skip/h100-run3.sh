#!/usr/bin/env bash
# One H100 call: the shipped defaults (unfused descent, cave skip for camera
# rays, texel beam) against the walk without the cave skip and the texel
# beam; then where the march's
# time goes (diagnostics: the same code plus round 2's shader-rewrite hook,
# `bench/ray-exact-ablation/round2/shader-sed-hook.patch`, rules in `sed/`:
# `cap0` stops every ray before its first iteration and drops the
# capped-ray counters, `nomarks` stamps no shadow block, both make wrong
# pictures on purpose; `markdedupe` filters a workgroup's repeated shadow
# stamps in workgroup memory first, the same picture). The protocol's
# twelve views, 1280x800, shadows, 20 frames.
# Carry `.gl`, `devbin` (strata.gz, shipped) and `devexp` (strata.gz, hook):
#   OUT=$OUT [REPS=2] bash bench/issue36-cave-skip/h100-run3.sh  (REPS=2: a second
# `neither` and `cap0` without the beam too)
set -u
for f in .gl/*.deb; do dpkg -x "$f" /; done; ldconfig
gunzip -c devbin/strata.gz > /tmp/strata; gunzip -c devexp/strata.gz > /tmp/strata-hook
chmod +x /tmp/strata /tmp/strata-hook
W=$(mktemp -d); export STRATA_CACHE_DIR=$W/cache
/tmp/strata generate --out "$W/world" > /dev/null
run() {
    local bin=$1 name=$2; shift 2
    env "$@" timeout 120 "$bin" compare --level "$W/world" --frames 20 --no-edits --methods ray-exact \
        --out "$W/$name" > "$W/$name.log" 2>&1 || echo "$name failed: $(tail -2 "$W/$name.log")"
}
SED=bench/issue36-cave-skip/sed
NEITHER="STRATA_EXACT_CAVE_SKIP=off STRATA_EXACT_BEAM_TEXELS=off"
REPS=${REPS:-1}
run /tmp/strata default-1
run /tmp/strata neither-1 $NEITHER
run /tmp/strata default-2
[ "$REPS" -ge 2 ] && run /tmp/strata neither-2 $NEITHER
run /tmp/strata-hook hook
run /tmp/strata-hook markdedupe STRATA_SHADER_SED_FILE=$SED/markdedupe.txt
run /tmp/strata-hook cap0 STRATA_SHADER_SED_FILE=$SED/cap0.txt
run /tmp/strata-hook nomarks STRATA_SHADER_SED_FILE=$SED/nomarks.txt
[ "$REPS" -ge 2 ] && run /tmp/strata-hook cap0-nobeam STRATA_SHADER_SED_FILE=$SED/cap0.txt STRATA_EXACT_BEAM=off
python3 bench/issue36-loop-bounding/summary_all.py "$W"/default-? "$W"/neither-? \
    "$W"/hook "$W"/markdedupe "$W"/cap0 "$W"/nomarks "$W"/cap0-nobeam \
    | tee "$OUT/summary3.txt"
mkdir -p "$OUT/h100c"
for d in "$W"/*/; do
    n=$(basename "$d"); case $n in world|cache) continue ;; esac
    cp "$d"/results-*.json "$OUT/h100c/$n.json"
done
(cd "$OUT" && tar czf h100c.tgz h100c && rm -rf h100c)
