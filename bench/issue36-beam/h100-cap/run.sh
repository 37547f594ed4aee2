#!/bin/bash
# Device run 32: ray-exact's beam cap (BEAM_CAP in ray_exact_beam.wgsl) swept by a text substitution in one binary; beam off as baseline.
for f in .gl/*.deb; do dpkg -x $f /; done; ldconfig
gunzip -c devbin/strata-exp.gz > /tmp/strata; chmod +x /tmp/strata
export STRATA_CACHE_DIR=/tmp/strata-cache
C="compare --methods ray-exact --no-edits --frames 20"
run() { name=$1; shift; env "$@" /tmp/strata $C --out /tmp/r-$name >> $OUT/log.txt 2>&1; cp /tmp/r-$name/results-*.json /tmp/res-$name.json; }
run off STRATA_EXACT_BEAM=off
for cap in 64 32 24 16 12 8; do run cap$cap "STRATA_SHADER_SED=BEAM_CAP: u32 = 64u=>BEAM_CAP: u32 = ${cap}u"; done
run cap64b "STRATA_SHADER_SED=BEAM_CAP: u32 = 64u=>BEAM_CAP: u32 = 64u"
run offb STRATA_EXACT_BEAM=off
cd /tmp; python3 - > $OUT/summary.txt <<'PY'
import json,glob,collections
for f in sorted(glob.glob('/tmp/res-*.json')):
    r=json.load(open(f)); rs=[x for x in r['rows'] if x['method']=='ray-exact']
    p=collections.defaultdict(list)
    if not rs:
        print(f, 'failed', str(r.get('failures'))[:200]); continue
    for x in rs:
        for q in x['passes']: p[q['label'].replace('ray-exact ','')].append(q['mean_ms'])
    print(f.split('/')[-1], 'frame', round(sum(x['gpu_ms_mean'] for x in rs)/len(rs),4), {k:round(sum(v)/len(v),4) for k,v in p.items()}, 'see', max(x['see_through'] for x in rs) if rs else None, len(r['failures'] if 'failures' in r else []))
PY
cp /tmp/res-cap24.json /tmp/res-cap64.json /tmp/res-off.json $OUT/
/tmp/strata --version >> $OUT/log.txt
