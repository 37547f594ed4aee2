"""The gameplay row of each `compare --gameplay` results file named on the
command line (a file, or a folder holding one): the frame alone and with
edits (GPU and wall clock, p50/p99/max ms), the edits' CPU time, and the
checks against a fresh build."""
import glob, json, os, sys
for a in sys.argv[1:]:
    f = a if os.path.isfile(a) else glob.glob(a + "/results-*.json")[0]
    r = json.load(open(f))["gameplay"]["rows"][0]
    q = lambda k: "/".join(f"{r[k][p]:.3f}" for p in ("p50", "p99", "max"))
    bad = [c for c in r["checks"] if c["differing_pixels"] or c["class_mismatch"]]
    print(os.path.basename(a), "| alone GPU", q("alone_gpu_ms"), "| with edits GPU", q("with_edits_gpu_ms"),
          "| with edits wall", q("with_edits_cpu_ms"), "| edits CPU", q("edit_cpu_ms"),
          "| checks", len(r["checks"]), "differing", len(bad))
