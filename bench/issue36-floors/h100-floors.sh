#!/usr/bin/env bash
# One H100 call: where `ray-exact`'s fixed costs go, and a few same-image
# variants, all through round 2's shader-rewrite hook
# (`bench/ray-exact-ablation/round2/shader-sed-hook.patch`; rules in `sed/`).
# Diagnostics (wrong pictures on purpose): `shadesky` shades no hit,
# `notaps` reads no shadow tap, `flatnormal` fetches no neighbour for the
# normal, `palette` reads no palette entry, `floor` = `cap0nostats` with the
# beam off (the march stops every ray at once and keeps no statistics).
# Same pictures: `nostats` (no most-iterations statistic: no workgroup atomic,
# barrier or global atomicMax a workgroup), `levelswg` (the level table read
# from workgroup memory, not indexed in the uniform buffer), `roundsN` (the
# camera beam's wide search stopped after N rounds, 8 shipped), `widepass`
# (the beam in a pre-pass), `srN` (the shadow blocks' search N rounds).
# Carry `.gl`, `devexp` (strata.gz with the hook).  OUT=$OUT bash this
set -u
for f in .gl/*.deb; do dpkg -x "$f" /; done; ldconfig
gunzip -c devexp/strata.gz > /tmp/strata-hook; chmod +x /tmp/strata-hook
W=$(mktemp -d); export STRATA_CACHE_DIR=$W/cache
/tmp/strata-hook generate --out "$W/world" > /dev/null
S=bench/issue36-floors/sed
run() {
    local name=$1; shift 1
    env "$@" timeout 120 /tmp/strata-hook compare --level "$W/world" --frames 20 --no-edits --methods ray-exact \
        --out "$W/$name" > "$W/$name.log" 2>&1 || echo "$name failed: $(tail -2 "$W/$name.log")"
}
run base-1
run nostats STRATA_SHADER_SED_FILE=$S/nostats.txt
run levelswg STRATA_SHADER_SED_FILE=$S/levelswg.txt
run rounds2 STRATA_SHADER_SED_FILE=$S/rounds2.txt
run rounds3 STRATA_SHADER_SED_FILE=$S/rounds3.txt
run rounds4 STRATA_SHADER_SED_FILE=$S/rounds4.txt
run widepass STRATA_EXACT_BEAM=wide-pass
run sr2 STRATA_EXACT_SHADOW_ROUNDS=2
run sr4 STRATA_EXACT_SHADOW_ROUNDS=4
run shadesky STRATA_SHADER_SED_FILE=$S/shadesky.txt
run notaps STRATA_SHADER_SED_FILE=$S/notaps.txt
run flatnormal STRATA_SHADER_SED_FILE=$S/flatnormal.txt
run palette STRATA_SHADER_SED_FILE=$S/palette.txt
run floor STRATA_SHADER_SED_FILE=$S/cap0nostats.txt STRATA_EXACT_BEAM=off
run base-2
python3 bench/issue36-loop-bounding/summary_all.py "$W"/base-1 "$W"/base-2 "$W"/nostats "$W"/levelswg \
    "$W"/rounds? "$W"/widepass "$W"/sr? "$W"/shadesky "$W"/notaps "$W"/flatnormal "$W"/palette "$W"/floor \
    | tee "$OUT/summary.txt"
mkdir -p "$OUT/runs"
for d in "$W"/*/; do
    n=$(basename "$d"); case $n in world|cache) continue ;; esac
    cp "$d"/results-*.json "$OUT/runs/$n.json"; grep -c STRATA_SHADER_SED "$W/$n.log" > "$OUT/runs/$n.sed-count"
done
(cd "$OUT" && tar czf runs.tgz runs && rm -rf runs)
