#!/usr/bin/env bash
# One H100 call: one binary (`devbin/strata.xz`), `ray-exact` with the
# terrain walk (the default, STRATA_EXACT_TEXEL_BLOCKS=off) and the texel
# plane's two walks (=plane, =beside), alternated, REPS (3) runs each: the
# protocol's twelve views, 1280x800, shadows, 20 frames. Carry `.gl` and
# `devbin`.
#   OUT=$OUT [REPS=3] bash bench/issue36-texel-blocks/h100-ab.sh
set -u
for f in .gl/*.deb; do dpkg -x "$f" /; done; ldconfig
python3 -c 'import lzma, sys; sys.stdout.buffer.write(lzma.open(sys.argv[1]).read())' devbin/strata.xz > /tmp/strata
chmod +x /tmp/strata
W=$(mktemp -d); export STRATA_CACHE_DIR=$W/cache
/tmp/strata generate --out "$W/world" > /dev/null
run() {
    local name=$1; shift
    env "$@" timeout 120 /tmp/strata compare --level "$W/world" --frames 20 --no-edits --methods ray-exact \
        --out "$W/$name" > "$W/$name.log" 2>&1 || echo "$name failed: $(tail -2 "$W/$name.log")"
}
for k in $(seq 1 "${REPS:-3}"); do
    for walk in off plane beside; do
        run $walk-$k STRATA_EXACT_TEXEL_BLOCKS=$walk
    done
done
python3 bench/issue36-loop-bounding/summary_all.py "$W"/off-* "$W"/plane-* "$W"/beside-* | tee "$OUT/summary.txt"
mkdir -p "$OUT/runs"
for d in "$W"/*/; do
    n=$(basename "$d"); case $n in world|cache) continue ;; esac
    cp "$d"/results-*.json "$OUT/runs/$n.json"
done
(cd "$OUT" && tar czf runs.tgz runs && rm -rf runs)
