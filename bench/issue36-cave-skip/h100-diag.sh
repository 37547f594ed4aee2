#!/usr/bin/env bash
# Where the march's time goes now (diagnostics, pictures wrong on purpose):
# the shipped binary plus round 2's shader-rewrite hook
# (`bench/ray-exact-ablation/round2/shader-sed-hook.patch`, gzipped as
# devexp/strata.gz), the rules in `sed/`: `cap0` stops every ray before its
# first iteration (and drops the capped-ray counters, which would otherwise
# be one atomic on one address per pixel); `nomarks` stamps no shadow block.
#   OUT=$OUT bash bench/issue36-cave-skip/h100-diag.sh
set -u
for f in .gl/*.deb; do dpkg -x "$f" /; done; ldconfig
gunzip -c devexp/strata.gz > /tmp/strata-hook; chmod +x /tmp/strata-hook
S=/tmp/strata-hook
W=$(mktemp -d); export STRATA_CACHE_DIR=$W/cache
"$S" generate --out "$W/world" > /dev/null
run() {
    local name=$1; shift
    env "$@" timeout 120 "$S" compare --level "$W/world" --frames 20 --no-edits --methods ray-exact \
        --out "$W/$name" > "$W/$name.log" 2>&1 || echo "$name failed: $(tail -2 "$W/$name.log")"
}
SED=bench/issue36-cave-skip/sed
for rep in 1 2; do
    run "base-$rep"
    run "cap0-$rep" STRATA_SHADER_SED_FILE=$SED/cap0.txt
done
run cap0-nobeam STRATA_SHADER_SED_FILE=$SED/cap0.txt STRATA_EXACT_BEAM=off
run nomarks STRATA_SHADER_SED_FILE=$SED/nomarks.txt
run cap0-nomarks STRATA_SHADER_SED_FILE=$SED/cap0-nomarks.txt
run nobeam STRATA_EXACT_BEAM=off
python3 bench/issue36-loop-bounding/summary_all.py "$W"/base-? "$W"/cap0-? "$W"/cap0-nobeam "$W"/nomarks "$W"/cap0-nomarks "$W"/nobeam \
    | tee "$OUT/summary-diag.txt"
