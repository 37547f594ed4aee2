"""Per method: mean GPU ms and mean FLIP over the views of each results
folder named on the command line (a path, or a name under /tmp)."""
import glob, json, os, sys
for v in sys.argv[1:]:
    d = v if os.path.isdir(v) else f"/tmp/{v}"
    f = glob.glob(f"{d}/results-*.json")
    if not f:
        print(v, "missing"); continue
    rows = json.load(open(f[0]))["rows"]
    by = {}
    for x in rows:
        by.setdefault(x["method"], []).append(x)
    for m, rs in by.items():
        ms = sum(x["gpu_ms_mean"] for x in rs) / len(rs)
        flip = sum(x["flip"]["mean"] for x in rs) / len(rs)
        st = max(x["see_through"] for x in rs)
        passes = {}
        for x in rs:
            for p in x.get("passes", []):
                passes[p["label"]] = passes.get(p["label"], 0) + p["mean_ms"] / len(rs)
        split = ", ".join(f"{k}: {t:.4f}" for k, t in passes.items()) if m.startswith(("ray-exact", "sliced")) else ""
        print(f"{os.path.basename(v.rstrip('/')):10s} {m:24s} ms {ms:8.4f} flip {flip:.4f} see-through max {st:.4f} {split}")
