#!/usr/bin/env bash
# One H100 call: what bounds the march? The change's code with the
# shader-rewrite hook (`devexp3`), each rule adding work to every march
# iteration that changes no result: `p1tex` one more terrain fetch per
# column test, `p2alu` 16 dependent multiply-adds per iteration, `p3load`
# one more (cached) storage-buffer load per iteration. Carry `.gl`, `devexp3`.
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
unpack devexp3 /tmp/strata-exp3; chmod +x /tmp/strata-exp3
W=$(mktemp -d); export STRATA_CACHE_DIR=$W/cache
/tmp/strata-exp3 generate --out "$W/world" > /dev/null
S=bench/issue36-floors/sed
run() {
    local name=$1; shift 1
    env "$@" timeout 120 /tmp/strata-exp3 compare --level "$W/world" --frames 20 --no-edits --methods ray-exact \
        --out "$W/$name" > "$W/$name.log" 2>&1 || echo "$name failed: $(tail -2 "$W/$name.log")"
}
run hook-1
run p1tex STRATA_SHADER_SED_FILE=$S/p1tex.txt
run p2alu STRATA_SHADER_SED_FILE=$S/p2alu.txt
run p3load STRATA_SHADER_SED_FILE=$S/p3load.txt
run hook-2
python3 bench/issue36-loop-bounding/summary_all.py "$W"/hook-? "$W"/p1tex "$W"/p2alu "$W"/p3load | tee "$OUT/perturb.txt"
