#!/usr/bin/env bash
# One H100 call, the hook build of cb57e76 (`devhook`): the beam's texel test
# for boxes up to 2 or 3 texels wide (`tex2`, `tex3`: every texel of the
# box, not only boxes a texel wide; the same pictures), and two more
# perturbations of the march (`p3uniform`: one more load per iteration at
# one address for the whole ray set, off the iteration count; `p3off`: the
# `p3load` load whose result the branch needs only when cap == 7).
# Carry `.gl`, `devhook`.   OUT=$OUT bash this
set -u
for f in .gl/*.deb; do dpkg -x "$f" /; done; ldconfig
python3 -c 'import lzma, sys; sys.stdout.buffer.write(lzma.open(sys.argv[1]).read())' devhook/strata.xz > /tmp/strata-hook
chmod +x /tmp/strata-hook
W=$(mktemp -d); export STRATA_CACHE_DIR=$W/cache
/tmp/strata-hook generate --out "$W/world" > /dev/null
S=bench/issue36-floors/sed
run() {
    local name=$1; shift 1
    env "$@" timeout 120 /tmp/strata-hook compare --level "$W/world" --frames 20 --no-edits --methods ray-exact \
        --out "$W/$name" > "$W/$name.log" 2>&1 || echo "$name failed: $(tail -2 "$W/$name.log")"
}
run hook-1
run tex2 STRATA_SHADER_SED_FILE=$S/tex2.txt
run tex3 STRATA_SHADER_SED_FILE=$S/tex3.txt
run hook-2
run p3uniform STRATA_SHADER_SED_FILE=$S/p3uniform.txt
run p3off STRATA_SHADER_SED_FILE=$S/p3off.txt
run tex3-2 STRATA_SHADER_SED_FILE=$S/tex3.txt
python3 bench/issue36-loop-bounding/summary_all.py "$W"/hook-? "$W"/tex* "$W"/p3* | tee "$OUT/texels.txt"
