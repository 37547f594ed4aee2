#!/usr/bin/env bash
# Calls 1 and 2 of this folder: one binary, the cave skip and the beam's
# texel test each on and off, alternated, twice each, with the fused
# descent on (call 1, `FUSED=on`, the default then) or off (call 2,
# `FUSED=off`, the default now); call 1 also the walk before both, unfused
# (the march before `dbd4d96`). The protocol's twelve views at 1280x800
# with shadows, 20 frames.
# Run from the repository root on the device with `devbin/strata` (release,
# stripped; gzipped as devbin/strata.gz is fine) and `.gl/` carried:
#   OUT=$OUT bash bench/issue36-cave-skip/h100-run.sh
set -u
for f in .gl/*.deb; do dpkg -x "$f" /; done; ldconfig
[ -e devbin/strata.gz ] && gunzip -f devbin/strata.gz && chmod +x devbin/strata
S=${STRATA:-devbin/strata}
W=$(mktemp -d); export STRATA_CACHE_DIR=$W/cache
"$S" generate --out "$W/world" > /dev/null
nvidia-smi --query-gpu=name,driver_version --format=csv,noheader > "$OUT/gpu.txt" 2>&1
FUSED=${FUSED:-on}
run() {
    local name=$1; shift
    env STRATA_EXACT_FUSED_DESCENT="$FUSED" "$@" timeout 120 "$S" compare --level "$W/world" --frames 20 --no-edits --methods ray-exact \
        --out "$W/$name" > "$W/$name.log" 2>&1 || echo "$name failed: $(tail -2 "$W/$name.log")"
}
for rep in 1 2; do
    run "both-$rep"
    run "nocave-$rep" STRATA_EXACT_CAVE_SKIP=off
    run "notexels-$rep" STRATA_EXACT_BEAM_TEXELS=off
    run "neither-$rep" STRATA_EXACT_CAVE_SKIP=off STRATA_EXACT_BEAM_TEXELS=off
done
run "neither-unfused" STRATA_EXACT_CAVE_SKIP=off STRATA_EXACT_BEAM_TEXELS=off STRATA_EXACT_FUSED_DESCENT=off
python3 bench/issue36-loop-bounding/summary_all.py "$W"/both-? "$W"/nocave-? "$W"/notexels-? "$W"/neither-? "$W"/neither-unfused \
    | tee "$OUT/summary.txt"
mkdir -p "$OUT/h100"
for d in "$W"/*/; do
    n=$(basename "$d"); [ "$n" = world ] || [ "$n" = cache ] && continue
    cp "$d"/results-*.json "$OUT/h100/$n.json" 2>/dev/null
done
(cd "$OUT" && tar czf h100.tgz h100 && rm -rf h100)
