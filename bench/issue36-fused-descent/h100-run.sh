#!/usr/bin/env bash
# The H100 call this folder still needs: one binary, the fused descent on and
# off, twice each, the protocol's twelve views at 1280x800 with shadows.
# Run from the repository root on the device with `devbin/strata` (release,
# stripped) and `.gl/` carried (see bench/issue36-vange/README.md):
#   OUT=$OUT bash bench/issue36-fused-descent/h100-run.sh
set -u
for f in .gl/*.deb; do dpkg -x "$f" /; done; ldconfig
S=${STRATA:-devbin/strata}
W=$(mktemp -d); export STRATA_CACHE_DIR=$W/cache
"$S" generate --out "$W/world" > /dev/null
nvidia-smi --query-gpu=name,driver_version --format=csv,noheader > "$OUT/gpu.txt" 2>&1
for rep in 1 2; do
    "$S" compare --level "$W/world" --frames 20 --no-edits --methods ray-exact --out "$W/fused-$rep" > /dev/null 2>&1
    STRATA_EXACT_FUSED_DESCENT=off "$S" compare --level "$W/world" --frames 20 --no-edits --methods ray-exact \
        --out "$W/unfused-$rep" > /dev/null 2>&1
done
python3 bench/issue36-loop-bounding/summary_all.py "$W"/fused-* "$W"/unfused-* | tee "$OUT/summary.txt"
mkdir -p "$OUT/h100"
for d in "$W"/fused-* "$W"/unfused-*; do cp "$d"/results-*.json "$OUT/h100/$(basename "$d").json"; done
(cd "$OUT" && tar czf h100.tgz h100 && rm -rf h100)
