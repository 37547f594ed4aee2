#!/usr/bin/env bash
# One H100 call: the march fetching ahead (`EXACT_PREFETCH`, `devpf`)
# against the same binary with it off and against the last commit
# (`devnew`, cb57e76), alternated; then fused descent with it on.
# Carry `.gl`, `devnew`, `devpf`.   OUT=$OUT [REPS=2] bash this
set -u
for f in .gl/*.deb; do dpkg -x "$f" /; done; ldconfig
unpack() {
    if [ -f "$1/strata.xz" ]; then
        python3 -c 'import lzma, sys; sys.stdout.buffer.write(lzma.open(sys.argv[1]).read())' "$1/strata.xz" > "$2"
    else
        gunzip -c "$1/strata.gz" > "$2"
    fi
    chmod +x "$2"
}
unpack devnew /tmp/strata-base; unpack devpf /tmp/strata-pf
W=$(mktemp -d); export STRATA_CACHE_DIR=$W/cache
/tmp/strata-pf generate --out "$W/world" > /dev/null
run() {
    local bin=$1 name=$2; shift 2
    env "$@" timeout 120 "$bin" compare --level "$W/world" --frames 20 --no-edits --methods ray-exact \
        --out "$W/$name" > "$W/$name.log" 2>&1 || echo "$name failed: $(tail -2 "$W/$name.log")"
}
for k in $(seq 1 "${REPS:-2}"); do
    run /tmp/strata-base base-$k
    run /tmp/strata-pf prefetch-$k
    run /tmp/strata-pf off-$k STRATA_EXACT_PREFETCH=off
done
run /tmp/strata-pf prefetch-fused STRATA_EXACT_FUSED_DESCENT=on
python3 bench/issue36-loop-bounding/summary_all.py "$W"/base-* "$W"/prefetch-* "$W"/off-* | tee "$OUT/summary.txt"
mkdir -p "$OUT/runs"
for d in "$W"/*/; do
    n=$(basename "$d"); case $n in world|cache) continue ;; esac
    cp "$d"/results-*.json "$OUT/runs/$n.json"
done
(cd "$OUT" && tar czf runs.tgz runs && rm -rf runs)
