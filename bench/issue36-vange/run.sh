#!/usr/bin/env bash
# Issue 36: vange-rs and Strata side by side on one GPU, in one call.
#
# Runs on the device machine from the repository root, with nothing
# installed there: the binaries come in git-ignored folders named in the
# call's `carry`:
#   devbin/strata          Strata (release), the lead's
#   devbin-vange/level     vange-rs's `level` (release, stripped; built from
#                          kvark/vange-rs, commit in devbin-vange/COMMIT),
#                          with its shaders in devbin-vange/res/shader
#   .gl/*.deb              the GL/Vulkan loaders (unpacked below)
# Both draw the same generated world (`strata generate`, the built-in
# world's seed and size) over its twelve views at 1280x800 with shadows, 20
# timed frames a view; Strata with `--vange-rs-mid` (vange-rs's cave
# ceiling rule). vange-rs runs headless (`--snapshot`, no window or display)
# and times each frame with GPU timestamps (`gpu_avg_ms` of `--bench-out`).
#
# Environment (all optional):
#   STRATA, VANGE       the two binaries (defaults above)
#   OUT                 where results go (default: $OUT of the device, else out/issue36-vange)
#   STRATA_METHODS      Strata's --methods (default: the fragment A/B below)
#   VANGE_TERRAINS      vange-rs terrains, space-separated NAME=ARGS pairs
#                       (default: ray and voxel at Strata's settings)
#   VANGE_SHADOW        vange-rs's shadow flag (default --shadow-ray: a
#                       1024² height-field ray-traced shadow map, as Strata's)
#   FRAMES, SIZE        default 20, 1280x800
#   VANGE_WARMUP        vange-rs's untimed frames before the timed ones (default 30)
#
# Writes $OUT/vange.json (vange-rs's bench JSON per terrain and view),
# $OUT/strata/results-*.json + report.md, $OUT/table.md, and prints the table.
set -euo pipefail

if ! ldconfig -p 2>/dev/null | grep -q libvulkan; then
    for f in .gl/*.deb; do dpkg -x "$f" /; done
    ldconfig
fi
if [ -e /usr/local/nvidia/share/vulkan/icd.d/nvidia_icd.json ]; then
    export VK_DRIVER_FILES=${VK_DRIVER_FILES:-/usr/local/nvidia/share/vulkan/icd.d/nvidia_icd.json}
    export __EGL_VENDOR_LIBRARY_FILENAMES=${__EGL_VENDOR_LIBRARY_FILENAMES:-/usr/local/nvidia/share/glvnd/egl_vendor.d/10_nvidia.json}
fi

STRATA=${STRATA:-devbin/strata}
VANGE=${VANGE:-devbin-vange/level}
OUT=${OUT:-out/issue36-vange}
FRAMES=${FRAMES:-20}
SIZE=${SIZE:-1280x800}
W=${SIZE%x*}
H=${SIZE#*x}
STRATA_METHODS=${STRATA_METHODS:-ray:128,ray:128/nobeam,voxel,voxel:/nobeam}
VANGE_TERRAINS=${VANGE_TERRAINS:-"ray:128=RayTraced,--ray-steps,128 voxel=RayVoxelTraced,--voxel-size,4,8,2,--voxel-steps,100"}
VANGE_SHADOW=${VANGE_SHADOW:---shadow-ray}
VANGE_WARMUP=${VANGE_WARMUP:-30}
VANGE_DIR=$(cd "$(dirname "$VANGE")" && pwd)
VANGE_BIN=$(basename "$VANGE")
STRATA=$(cd "$(dirname "$STRATA")" && pwd)/$(basename "$STRATA")
mkdir -p "$OUT"
OUT=$(cd "$OUT" && pwd)
rm -f "$OUT/vange.json"
WORK=$(mktemp -d)
export STRATA_CACHE_DIR="$WORK/cache"

echo "== world"
"$STRATA" --version || true
"$STRATA" generate --out "$WORK/world"
VIEWS="$WORK/world/views.txt"
grep -v '^\s*#' "$VIEWS" | grep -v '^\s*$' > "$WORK/views"
cat "$WORK/views"

echo "== vange-rs"
cat "$VANGE_DIR/COMMIT" 2>/dev/null || true
for pair in $VANGE_TERRAINS; do
    method=${pair%%=*}
    args=${pair#*=}
    IFS=',' read -r terrain rest <<< "$args"
    # `--voxel-size,4,8,2` travels as commas: put the flags back together.
    extra=()
    if [ -n "${rest:-}" ]; then
        extra=($(echo "$rest" | sed -E 's/,(--)/ \1/g; s/(--[a-z-]+),/\1 /g'))
    fi
    tag=${method//[:\/]/-}
    mkdir -p "$WORK/vange-$tag"
    while read -r name spec pitch; do
        pos=${spec%%:*}
        rest_spec=${spec#*:}
        yaw=${rest_spec%%:*}
        rest_spec=${rest_spec#*:}
        eye=${rest_spec%%:*}
        under=()
        case "$spec" in *:under) under=(--fp-under) ;; esac
        # vange-rs reads its shaders from res/shader under the working
        # directory (devbin-vange/res/shader); `=` keeps negative numbers values.
        (cd "$VANGE_DIR" && "./$VANGE_BIN" "$WORK/world/world.ini" --snapshot "$WORK/vange-$tag/$name.png" \
            --terrain "$terrain" "${extra[@]}" --width "$W" --height "$H" \
            --fp "$pos" --fp-yaw="$yaw" --fp-pitch="$pitch" --fp-height "$eye" "${under[@]}" \
            --near 1 --far 600 $VANGE_SHADOW --warmup "$VANGE_WARMUP" --frames "$FRAMES" \
            --bench-out "$WORK/vange-$tag/$name.json") > "$WORK/vange-$tag/$name.log" 2>&1 \
            || { echo "vange-rs $method $name failed:"; tail -5 "$WORK/vange-$tag/$name.log"; }
        printf '%s %s: %s\n' "$method" "$name" "$(grep -o '"gpu_avg_ms": [^,]*' "$WORK/vange-$tag/$name.json" 2>/dev/null || echo missing)"
    done < "$WORK/views"
    # One file for every terrain (a call brings back at most 8 files).
    python3 - "$WORK/vange-$tag" "$OUT/vange.json" "$method" <<'PY'
import json, os, sys
src, dst, method = sys.argv[1], sys.argv[2], sys.argv[3]
views = {}
for f in sorted(os.listdir(src)):
    if f.endswith('.json'):
        views[f[:-5]] = json.load(open(os.path.join(src, f)))
all_ = json.load(open(dst)) if os.path.exists(dst) else {}
all_[method] = views
json.dump(all_, open(dst, 'w'), indent=1)
PY
done

echo "== Strata"
"$STRATA" compare --level "$WORK/world" --vange-rs-mid --no-edits --frames "$FRAMES" --size "$SIZE" \
    --methods "$STRATA_METHODS" --out "$OUT/strata" 2>&1 | tail -5
# Only the results file and the report come back (the pictures stay).
find "$OUT/strata" -mindepth 1 -not -name 'results-*.json' -not -name 'report.md' -exec rm -rf {} + 2>/dev/null || true

echo "== table"
python3 - "$OUT" "$WORK/views" "$VANGE_TERRAINS" <<'PY' | tee "$OUT/table.md"
import glob, json, os, sys
out, views_file, terrains = sys.argv[1], sys.argv[2], sys.argv[3].split()
views = [l.split()[0] for l in open(views_file)]
res = json.load(open(glob.glob(os.path.join(out, 'strata', 'results-*.json'))[0]))
strata = {}
for row in res['rows']:
    strata.setdefault(row['method'], {})[row['view']] = row
def mean(xs):
    xs = [x for x in xs if x is not None]
    return sum(xs) / len(xs) if xs else None
vange = {}
runs = json.load(open(os.path.join(out, 'vange.json')))
for pair in terrains:
    method = pair.split('=')[0]
    data = runs.get(method, {})
    vange[method] = mean([data.get(v, {}).get('gpu_avg_ms') for v in views])
print(f"Mean GPU ms over {len(views)} views ({res['adapter']['name'] if isinstance(res.get('adapter'), dict) else res.get('adapter')}); Strata revision {res.get('source_revision')}\n")
print('| Strata method | vange-rs | Strata frame | method passes | ꟻLIP | ratio |')
print('|---|---:|---:|---:|---:|---:|')
for method, per_view in strata.items():
    base = method.split('/')[0] if method.startswith('ray') else method.split(':')[0]
    v = vange.get(method) or vange.get(base) or vange.get(method.split(':')[0])
    frame = mean([per_view[x]['gpu_ms_mean'] for x in views if x in per_view])
    passes = mean([sum(p['mean_ms'] for p in per_view[x]['passes'] if p['label'] != 'shadow')
                   for x in views if x in per_view])
    flip = mean([(per_view[x].get('flip') or {}).get('mean') for x in views if x in per_view])
    ratio = f'{frame / v:.2f}' if v else '-'
    vs = f'{v:.2f}' if v else '-'
    fl = f'{flip:.4f}' if flip is not None else '-'
    print(f'| {method} | {vs} | {frame:.3f} | {passes:.3f} | {fl} | {ratio} |')
PY
rm -rf "$WORK"
