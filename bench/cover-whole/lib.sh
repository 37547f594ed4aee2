# Shared by this folder's scripts (sourced; W, OUT and /tmp/strata set).

# The moving camera: `compare --gameplay` along the video's path (64 edits
# a frame, then each camera again without one), cover on and off; one
# summary line each.
gameplay_on_off() {
    for v in on off; do
        gameplay_run /tmp/strata $v STRATA_EXACT_COVER=$([ $v = on ] && echo 256 || echo off)
    done
}

# One gameplay run of binary $1, named gameplay-$2, with environment $3.
gameplay_run() {
    local v=$2
    env $3 timeout 150 "$1" compare \
        --level "$W/world" --gameplay --view-names hangar \
        --methods ray-exact --out "$W/gameplay-$v" > "$OUT/gameplay-$v.log" 2>&1 \
        || echo "gameplay $v failed: $(tail -2 "$OUT/gameplay-$v.log")"
    python3 - "$W/gameplay-$v" <<'PY' | tee -a "$OUT/summary.txt"
import glob, json, sys
r = json.load(open(glob.glob(sys.argv[1] + "/results-*.json")[0]))["gameplay"]["rows"][0]
f = lambda k: "/".join(f"{r[k][q]:.4f}" for q in ("p50", "p99", "max"))
print(sys.argv[1].rsplit("/", 1)[1], "frame alone GPU p50/p99/max", f("alone_gpu_ms"), "with edits", f("with_edits_gpu_ms"), "alone CPU", f("alone_cpu_ms"))
PY
}

# Every run's results JSON into $OUT/runs.tgz.
collect_runs() {
    mkdir -p "$OUT/runs"
    for d in "$W"/*/; do
        n=$(basename "$d"); case $n in world|cache) continue ;; esac
        for f in "$d"/*.json; do [ -e "$f" ] && cp "$f" "$OUT/runs/$n-$(basename "$f")"; done
    done
    (cd "$OUT" && tar czf runs.tgz runs && rm -rf runs)
}
