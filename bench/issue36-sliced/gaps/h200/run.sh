#!/bin/bash
# Device run 52: plain sliced's per-pixel gap pass against /fragwalk (the shipped per-fragment walks), refined with and without the steep marks; held-out see-through of the gap pass.
for f in .gl/*.deb; do dpkg -x $f /; done; ldconfig
gunzip -c devbin/strata-rows.gz > /tmp/strata; chmod +x /tmp/strata
export STRATA_CACHE_DIR=/tmp/strata-cache
S=/tmp/strata
nvidia-smi --query-gpu=name,driver_version --format=csv > $OUT/gpu.txt 2>&1
for s in 7 9 36; do $S generate --seed $s --out /tmp/w$s >> $OUT/log.txt 2>&1 & done
$S generate --seed 5 --size 512x1024 --out /tmp/s5 >> $OUT/log.txt 2>&1 &
wait
timed() { $S compare --frames 20 --methods $2 --no-edits --out /tmp/b-$1 >> $OUT/log.txt 2>&1; }
held() { for w in w7 w9 w36 s5; do $S compare --level /tmp/$w --size 320x200 --frames 1 --warmup 1 --hold-busy 0 --methods $2 --no-edits --out /tmp/h-$1-$w >> $OUT/log.txt 2>&1; done; }
timed fragwalk sliced:512/fragwalk
timed gaps sliced:512
held gaps sliced:512,sliced:512/refine
timed refine sliced:512/refine
timed refine-fragwalk sliced:512/refine/fragwalk
timed fragwalk2 sliced:512/fragwalk
timed gaps2 sliced:512
cd /tmp; python3 - > $OUT/summary.txt <<'PY'
import json,glob
for v in ['fragwalk','gaps','refine','refine-fragwalk','fragwalk2','gaps2']:
    out=[v]
    fs=glob.glob(f'/tmp/b-{v}/results-*.json')
    if fs:
        r=json.load(open(fs[0])); rs=r['rows']
        out.append(f"builtin ms {sum(x['gpu_ms_mean'] for x in rs)/len(rs):.3f} see max {max(x['see_through'] for x in rs):.3f} flip {sum(x['flip']['mean'] for x in rs)/len(rs):.4f} coh {sum(x['coherence'] for x in rs)/len(rs):.3f} p95 {sum(x['depth_p95'] for x in rs)/len(rs):.2f} | " + ' '.join(f"{x['view']}:{x['gpu_ms_mean']:.2f}" for x in rs))
    for w in ['w7','w9','w36','s5']:
        fs=glob.glob(f'/tmp/h-{v}-{w}/results-*.json')
        if not fs: continue
        r=json.load(open(fs[0])); rs=r['rows']
        for m in sorted(set(x['method'] for x in rs)):
            mr=[x for x in rs if x['method']==m]
            worst=max(mr,key=lambda x:x['see_through'])
            out.append(f"{w} {m} see max {worst['see_through']:.3f} ({worst['view']})")
    print(' | '.join(out))
PY
for v in fragwalk gaps refine refine-fragwalk; do cp /tmp/b-$v/results-*.json $OUT/results-$v.json; done
cp /tmp/b-gaps/report.md $OUT/report-gaps.md
