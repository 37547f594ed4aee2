#!/usr/bin/env bash
# One H100 call: plain `sliced` with the gaps walked in the deferred
# shading's compute pass (`devbin/strata.xz`) against the fragment gap pass
# (`devbin/strata-edbff28.xz`), alternated in separate processes, REPS (2)
# runs each: the protocol's twelve views, 1280x800, shadows, 20 frames,
# `--vange-rs-mid`. Carry `.gl` and `devbin`.
#   OUT=$OUT [REPS=2] bash bench/sliced-gaps-compute/h100-ab.sh
set -u
for f in .gl/*.deb; do dpkg -x "$f" /; done; ldconfig
for b in strata strata-edbff28; do
    python3 -c 'import lzma, sys; sys.stdout.buffer.write(lzma.open(sys.argv[1]).read())' devbin/$b.xz > /tmp/$b
    chmod +x /tmp/$b
done
W=$(mktemp -d); export STRATA_CACHE_DIR=$W/cache
/tmp/strata generate --out "$W/world" > /dev/null
run() {
    timeout 150 "/tmp/$2" compare --level "$W/world" --vange-rs-mid --frames 20 --no-edits \
        --methods sliced:512 --out "$W/$1" > "$W/$1.log" 2>&1 || echo "$1 failed: $(tail -2 "$W/$1.log")"
}
for k in $(seq 1 "${REPS:-2}"); do
    run fragment-$k strata-edbff28
    run compute-$k strata
done
python3 bench/issue36-loop-bounding/summary_all.py "$W"/fragment-* "$W"/compute-* | tee "$OUT/summary.txt"
mkdir -p "$OUT/runs"
for d in "$W"/*/; do
    n=$(basename "$d"); case $n in world|cache) continue ;; esac
    cp "$d"/results-*.json "$OUT/runs/$n.json"
done
(cd "$OUT" && tar czf runs.tgz runs && rm -rf runs)
