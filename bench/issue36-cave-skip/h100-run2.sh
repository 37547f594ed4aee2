#!/usr/bin/env bash
# The third H100 call of this folder: the shipped defaults (unfused descent,
# cave skip for camera rays, texel beam) against the walk without the cave
# skip and the texel beam, and against the previous default (fused descent,
# neither), alternated, twice each; then every method once with the
# defaults. The protocol's twelve views, 1280x800, shadows, 20 frames.
# From the repository root on the device, `devbin/strata(.gz)` and `.gl/`
# carried:  OUT=$OUT bash bench/issue36-cave-skip/h100-run2.sh
set -u
for f in .gl/*.deb; do dpkg -x "$f" /; done; ldconfig
[ -e devbin/strata.gz ] && gunzip -f devbin/strata.gz && chmod +x devbin/strata
S=${STRATA:-devbin/strata}
W=$(mktemp -d); export STRATA_CACHE_DIR=$W/cache
"$S" generate --out "$W/world" > /dev/null
run() {
    local name=$1; shift
    env "$@" timeout 300 "$S" compare --level "$W/world" --frames 20 --no-edits ${M:+--methods "$M"} \
        --out "$W/$name" > "$W/$name.log" 2>&1 || echo "$name failed: $(tail -2 "$W/$name.log")"
}
M=ray-exact
for rep in 1 2; do
    run "default-$rep"
    run "neither-$rep" STRATA_EXACT_CAVE_SKIP=off STRATA_EXACT_BEAM_TEXELS=off
    run "previous-$rep" STRATA_EXACT_CAVE_SKIP=off STRATA_EXACT_BEAM_TEXELS=off STRATA_EXACT_FUSED_DESCENT=on
done
M=
run all
python3 bench/issue36-loop-bounding/summary_all.py "$W"/default-? "$W"/neither-? "$W"/previous-? "$W"/all \
    | tee "$OUT/summary3.txt"
mkdir -p "$OUT/h100c"
for d in "$W"/*/; do
    n=$(basename "$d"); case $n in world|cache) continue ;; esac
    cp "$d"/results-*.json "$OUT/h100c/$n.json"
done
cp "$W/all/report.md" "$OUT/h100c/all-report.md"
(cd "$OUT" && tar czf h100c.tgz h100c && rm -rf h100c)
