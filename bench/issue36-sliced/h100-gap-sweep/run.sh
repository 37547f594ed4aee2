#!/bin/bash
# Device run 41: plain sliced's gap walk, swept by text substitution in one binary: held-out worlds at 320x200 (see-through) and the built-in world at 1280x800 (ms).
for f in .gl/*.deb; do dpkg -x $f /; done; ldconfig
gunzip -c devbin/strata-exp.gz > /tmp/strata; chmod +x /tmp/strata
export STRATA_CACHE_DIR=/tmp/strata-cache
S=/tmp/strata
$S generate --seed 7 --out /tmp/w7 >> $OUT/log.txt 2>&1 &
$S generate --seed 9 --out /tmp/w9 >> $OUT/log.txt 2>&1 &
$S generate --seed 36 --out /tmp/w36 >> $OUT/log.txt 2>&1 &
$S generate --seed 5 --size 512x1024 --out /tmp/s5 >> $OUT/log.txt 2>&1 &
wait
variant() {
  v=$1; sed=$2
  for w in w7 w9 w36 s5; do
    STRATA_SHADER_SED="$sed" $S compare --level /tmp/$w --size 320x200 --frames 1 --warmup 1 --hold-busy 0 --methods sliced:512 --no-edits --out /tmp/h-$v-$w >> $OUT/log.txt 2>&1
  done
  STRATA_SHADER_SED="$sed" $S compare --frames 20 --methods sliced:512 --no-edits --out /tmp/b-$v >> $OUT/log.txt 2>&1
}
variant base "X=>X"
variant nowalk "GAP_MIN: f32 = 2.0=>GAP_MIN: f32 = 1e9"
variant g3 "GAP_MIN: f32 = 2.0=>GAP_MIN: f32 = 3.0"
variant g4 "GAP_MIN: f32 = 2.0=>GAP_MIN: f32 = 4.0"
variant f256 "FIRST_GAP_TEXELS: u32 = 1024u=>FIRST_GAP_TEXELS: u32 = 256u"
variant g3f256 "GAP_MIN: f32 = 2.0=>GAP_MIN: f32 = 3.0;FIRST_GAP_TEXELS: u32 = 1024u=>FIRST_GAP_TEXELS: u32 = 256u"
variant base2 "X=>X"
cd /tmp; python3 - > $OUT/summary.txt <<'PY'
import json,glob
for v in ['base','nowalk','g3','g4','f256','g3f256','base2']:
    out=[v]
    for w in ['w7','w9','w36','s5']:
        fs=glob.glob(f'/tmp/h-{v}-{w}/results-*.json')
        if not fs: out.append(w+' failed'); continue
        r=json.load(open(fs[0])); rs=r['rows']
        worst=max(rs,key=lambda x:x['see_through'])
        out.append(f"{w} see max {worst['see_through']:.3f} ({worst['view']})")
    fs=glob.glob(f'/tmp/b-{v}/results-*.json')
    if fs:
        r=json.load(open(fs[0])); rs=r['rows']
        out.append(f"builtin ms {sum(x['gpu_ms_mean'] for x in rs)/len(rs):.3f} see max {max(x['see_through'] for x in rs):.3f} flip {sum(x['flip']['mean'] for x in rs)/len(rs):.4f} coh {sum(x['coherence'] for x in rs)/len(rs):.3f}")
    print(' | '.join(out))
PY
cp /tmp/b-base/results-*.json $OUT/results-base.json
