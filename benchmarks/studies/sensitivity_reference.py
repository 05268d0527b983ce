"""The reference bearing's sensitivity ranking on docs/validation.md, at reduced size.

Runs (each unless DIR already holds its sensitivity.json)

    jaxbearing sensitivity benchmarks/studies/sensitivity_reference.toml --seeds 3 --window-revs 2 --out DIR/crn
    jaxbearing sensitivity benchmarks/studies/sensitivity_reference.toml --quick --out DIR/quick

and merges both files into benchmarks/results/sensitivity_reference.json with the commands and,
for the runs it made, their wall times. One core: `taskset -c 0 python benchmarks/studies/sensitivity_reference.py DIR`.
"""

from __future__ import annotations

import json
import pathlib
import sys
import time

from jaxbearing.cli import main
from jaxbearing.io import write_json

ROOT = pathlib.Path(__file__).resolve().parents[2]
CONFIG = "benchmarks/studies/sensitivity_reference.toml"
RUNS = {
    "crn": ["sensitivity", CONFIG, "--seeds", "3", "--window-revs", "2"],
    "quick": ["sensitivity", CONFIG, "--quick"],
}


def run(out: pathlib.Path) -> dict:
    doc: dict = {"config": CONFIG}
    for name, argv in RUNS.items():
        d = out / name
        entry = {"command": "jaxbearing " + " ".join(argv) + f" --out {d}"}
        if not (d / "sensitivity.json").is_file():
            t = time.perf_counter()
            code = main([*argv, "--out", str(d)])
            entry["wall_time_s"] = time.perf_counter() - t
            if code != 0:
                raise SystemExit(code)
        entry["result"] = json.loads((d / "sensitivity.json").read_text())
        doc[name] = entry
    return doc


if __name__ == "__main__":
    out = pathlib.Path(sys.argv[1] if len(sys.argv) > 1 else "sensitivity_reference")
    write_json(ROOT / "benchmarks/results/sensitivity_reference.json", run(out))
