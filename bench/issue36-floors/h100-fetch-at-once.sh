#!/usr/bin/env bash
# One H100 call: fetches issued together instead of one after another
# (`devhook2`, the change plus the hook) against cb57e76 (`devhook`), and
# the change with each of its three parts taken back by a rule of `sed/`
# (`old-march-cave`: the march reads a tile's cave word after its maximum;
# `old-beam-cave`: the beam's four cave words one after another;
# `old-texels`: the beam's texel test reads its four texels one after
# another). Alternated. Carry `.gl`, `devhook`, `devhook2`.   OUT=$OUT bash this
set -u
for f in .gl/*.deb; do dpkg -x "$f" /; done; ldconfig
for b in devhook devhook2; do
    python3 -c 'import lzma, sys; sys.stdout.buffer.write(lzma.open(sys.argv[1]).read())' $b/strata.xz > /tmp/$b
    chmod +x /tmp/$b
done
W=$(mktemp -d); export STRATA_CACHE_DIR=$W/cache
/tmp/devhook2 generate --out "$W/world" > /dev/null
S=bench/issue36-floors/sed
run() {
    local bin=$1 name=$2; shift 2
    env "$@" timeout 120 "$bin" compare --level "$W/world" --frames 20 --no-edits --methods ray-exact \
        --out "$W/$name" > "$W/$name.log" 2>&1 || echo "$name failed: $(tail -2 "$W/$name.log")"
}
for k in 1 2; do
    run /tmp/devhook base-$k
    run /tmp/devhook2 new-$k
done
run /tmp/devhook2 old-march-cave STRATA_SHADER_SED_FILE=$S/old-march-cave.txt
run /tmp/devhook2 old-beam-cave STRATA_SHADER_SED_FILE=$S/old-beam-cave.txt
run /tmp/devhook2 old-texels STRATA_SHADER_SED_FILE=$S/old-texels.txt
run /tmp/devhook base-3
run /tmp/devhook2 new-3
python3 bench/issue36-loop-bounding/summary_all.py "$W"/base-? "$W"/new-? "$W"/old-* | grep -v missing | tee "$OUT/fetch-at-once.txt"
