#!/usr/bin/env bash
# One H100 call: plain `sliced` shaded once a pixel after its marks (the
# default now) against `sliced:512/forward` (every kept fragment shaded in
# the slice pass, as before), one binary (`devbin/strata.xz`), beside
# vange-rs's `Sliced` on the same world (`../issue36-vange/run.sh`). Then
# the two alternated in separate processes (a later method in one `compare`
# process can drift slower). The protocol: twelve views, 1280x800, shadows,
# 20 frames, `--vange-rs-mid`. Carry `.gl`, `devbin` and `devbin-vange`.
#   OUT=$OUT [REPS=2] bash bench/sliced-deferred/h100-ab.sh
set -u
for f in .gl/*.deb; do dpkg -x "$f" /; done; ldconfig
python3 -c 'import lzma, sys; sys.stdout.buffer.write(lzma.open(sys.argv[1]).read())' devbin/strata.xz > devbin/strata
chmod +x devbin/strata devbin-vange/level
export VANGE_WARMUP=10
start=$(date +%s)
OUTH=$OUT
OUT=$OUTH/side STRATA_METHODS=sliced:512 \
    VANGE_TERRAINS="sliced:512=Sliced,--slice-layers,512" \
    timeout 300 bash bench/issue36-vange/run.sh > "$OUTH/side.log" 2>&1
echo "side rc $? after $(( $(date +%s) - start )) s" >> "$OUTH/side.log"
tail -4 "$OUTH/side.log"
W=$(mktemp -d); export STRATA_CACHE_DIR=$W/cache
devbin/strata generate --out "$W/world" > /dev/null
run() {
    timeout 150 devbin/strata compare --level "$W/world" --vange-rs-mid --frames 20 --no-edits \
        --methods "$2" --out "$W/$1" > "$W/$1.log" 2>&1 || echo "$1 failed: $(tail -2 "$W/$1.log")"
}
for k in $(seq 1 "${REPS:-2}"); do
    run forward-$k sliced:512/forward
    run deferred-$k sliced:512
done
echo "runs done after $(( $(date +%s) - start )) s"
python3 bench/issue36-loop-bounding/summary_all.py "$W"/forward-* "$W"/deferred-* | tee "$OUTH/summary.txt"
mkdir -p "$OUTH/runs"
for d in "$W"/*/; do
    n=$(basename "$d"); case $n in world|cache) continue ;; esac
    cp "$d"/results-*.json "$OUTH/runs/$n.json"
done
(cd "$OUTH" && tar czf runs.tgz runs && rm -rf runs)
