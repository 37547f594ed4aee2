#!/usr/bin/env bash
# One H100 call: the baseline binary (`devbin/strata.xz`) against the
# change (`devnew/strata.xz`), alternated, REPS (3) runs each: the protocol's
# twelve views, 1280x800, shadows, 20 frames, `ray-exact` only.
# Carry `.gl` and the two folders (BASE=devbin, NEW=devnew by default).
#   OUT=$OUT [REPS=3] [BASE=dir] [NEW=dir] bash this
set -u
for f in .gl/*.deb; do dpkg -x "$f" /; done; ldconfig
# A carried binary: DIR/strata.xz (smaller: the tree that travels is at most
# 64 MiB) or DIR/strata.gz.
unpack() {
    if [ -f "$1/strata.xz" ]; then
        python3 -c 'import lzma, sys; sys.stdout.buffer.write(lzma.open(sys.argv[1]).read())' "$1/strata.xz" > "$2"
    else
        gunzip -c "$1/strata.gz" > "$2"
    fi
}
unpack "${BASE:-devbin}" /tmp/strata-base; unpack "${NEW:-devnew}" /tmp/strata-new
chmod +x /tmp/strata-base /tmp/strata-new
W=$(mktemp -d); export STRATA_CACHE_DIR=$W/cache
/tmp/strata-new generate --out "$W/world" > /dev/null
run() {
    local bin=$1 name=$2; shift 2
    env "$@" timeout 120 "$bin" compare --level "$W/world" --frames 20 --no-edits --methods ray-exact \
        --out "$W/$name" > "$W/$name.log" 2>&1 || echo "$name failed: $(tail -2 "$W/$name.log")"
}
for k in $(seq 1 "${REPS:-3}"); do
    run /tmp/strata-base base-$k
    run /tmp/strata-new new-$k
done
python3 bench/issue36-loop-bounding/summary_all.py "$W"/base-* "$W"/new-* | tee "$OUT/summary.txt"
mkdir -p "$OUT/runs"
for d in "$W"/*/; do
    n=$(basename "$d"); case $n in world|cache) continue ;; esac
    cp "$d"/results-*.json "$OUT/runs/$n.json"
done
(cd "$OUT" && tar czf runs.tgz runs && rm -rf runs)
