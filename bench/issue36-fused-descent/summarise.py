"""Mean GPU ms, mean FLIP and the passes of each method over the views, for
each `strata compare` output folder named on the command line."""
import glob, json, os, sys
for d in sys.argv[1:]:
    f = glob.glob(os.path.join(d, "results-*.json"))
    if not f:
        print(d, "missing"); continue
    rs = json.load(open(f[0]))["rows"]
    by = {}
    for x in rs:
        by.setdefault(x["method"], []).append(x)
    for m, rows in by.items():
        passes = {}
        for x in rows:
            for p in x["passes"]:
                passes[p["label"]] = passes.get(p["label"], 0) + p["mean_ms"] / len(rows)
        ms = sum(x["gpu_ms_mean"] for x in rows) / len(rows)
        fl = [x["flip"]["mean"] for x in rows if x.get("flip")]
        flip = sum(fl) / len(fl) if fl else float("nan")
        split = ", ".join(f"{k}: {t:.4f}" for k, t in passes.items())
        print(f"{os.path.basename(d)} {m}: ms {ms:.4f} flip {flip:.4f} passes {{{split}}}")
