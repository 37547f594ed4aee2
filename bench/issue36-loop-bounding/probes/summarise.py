"""Mean GPU ms and mean FLIP of `ray-exact` over the views, per pass, for
each `strata compare` output folder /tmp/<name> named on the command line
(what every run-*.sh here prints into $OUT/summary.txt)."""
import glob
import json
import sys

for v in sys.argv[1:]:
    f = glob.glob(f"/tmp/{v}/results-*.json")
    if not f:
        print(v, "missing")
        continue
    rs = json.load(open(f[0]))["rows"]
    passes = {}
    for x in rs:
        for p in x["passes"]:
            passes[p["label"]] = passes.get(p["label"], 0) + p["mean_ms"] / len(rs)
    ms = sum(x["gpu_ms_mean"] for x in rs) / len(rs)
    flip = sum(x["flip"]["mean"] for x in rs) / len(rs)
    split = ", ".join(f"{k}: {t:.4f}" for k, t in passes.items())
    print(f"{v} ray-exact: ms {ms:.4f} flip {flip:.4f} passes {{{split}}}")
