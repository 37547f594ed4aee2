#!/usr/bin/env python3
"""Checks what the README's main command wrote: report.md, grid.png, and a
results file with a row for every method the adapter it ran on can run
(as `strata adapters --json` says), and no failed method."""

import json
import subprocess
import sys
from pathlib import Path


def fail(why: str) -> None:
    print(f"check_compare: {why}", file=sys.stderr)
    sys.exit(1)


def main() -> None:
    out, strata = Path(sys.argv[1]), sys.argv[2]
    for name in ("report.md", "grid.png"):
        f = out / name
        if not f.is_file() or f.stat().st_size == 0:
            fail(f"{f} is missing or empty")
    if (out / "grid.png").read_bytes()[:8] != b"\x89PNG\r\n\x1a\n":
        fail("grid.png is not a PNG")
    results = sorted(out.glob("results-*.json"))
    if len(results) != 1:
        fail(f"expected one results-*.json in {out}, found {len(results)}")
    run = json.loads(results[0].read_text())
    if not run.get("complete"):
        fail(f"{results[0]}: the run is not complete")
    if run.get("failures"):
        fail(f"{results[0]}: failures {run['failures']}")
    adapter = run["adapter"]
    listing = json.loads(
        subprocess.run(
            [strata, "adapters", "--backend", adapter["backend"], "--json"],
            check=True,
            capture_output=True,
            text=True,
        ).stdout
    )
    matches = [a for a in listing if a["name"] == adapter["name"]]
    if not matches:
        fail(f"adapter {adapter['name']} is not in `strata adapters`")
    runs = {m["name"] for m in matches[0]["methods"] if m["refused"] is None}
    if not runs:
        fail(f"adapter {adapter['name']} runs no method")
    rows = {r["method"].split(":")[0] for r in run["rows"]}
    missing = sorted(runs - rows)
    if missing:
        fail(f"{results[0]}: no rows for {', '.join(missing)}")
    views = sorted({r["view"] for r in run["rows"]})
    print(
        f"check_compare: {results[0].name}: {len(run['rows'])} rows, "
        f"{len(runs)} methods on {adapter['name']} ({adapter['backend']}), views {', '.join(views)}; "
        f"revision {run['source_revision']}; report.md and grid.png written"
    )


if __name__ == "__main__":
    main()
