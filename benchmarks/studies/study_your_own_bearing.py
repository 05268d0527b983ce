"""The steps of the tutorial "Your own bearing" (notebooks/06_your_own_bearing.ipynb, which times
them in one process at the size of its setting), timed at full size as separate processes: a
catalogue NU 214 (ISO 15 dimension series 02, bore 70 mm: 70 x 125 x 24 mm) from its boundary
dimensions to a settled run, each step the command a user types, run as its own process:

1. `jaxbearing config new --series 02 --bore-mm 70 --type NU --out nu214.toml`
2. `jaxbearing config check nu214.toml`
3. `jaxbearing zone --config nu214.toml`
4. `jaxbearing simulate --config nu214.toml --end arc --out run` (settled: auto settling from
   the skid start, an 8-revolution window, one seed; the file's placeholder operating point)

Recorded per step: the command, its exit status and wall time (process start to end, imports
included); for the run also its summary's simulated settling time and window, integrator
steps, compile and run wall time and the settled statistics the tutorial quotes (cage slip,
mean flange PV, contact height, each with its 95 % CI). The machine block records the load
average: on the shared 2-core machine the times depend on what else runs.

    python benchmarks/studies/study_your_own_bearing.py [--quick]

Quick mode: 11 slices and a 2-revolution window (not the tutorial's numbers).
"""

from __future__ import annotations

import json
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

sys.path[:0] = [str(Path(__file__).resolve().parent), str(Path(__file__).resolve().parents[1])]

import _common  # noqa: E402

NAME = "study_your_own_bearing"


def _run(args: list[str], cwd: Path) -> dict:
    exe = shutil.which("jaxbearing") or str(Path(sys.executable).with_name("jaxbearing"))
    _common.log(f"{NAME}: jaxbearing {' '.join(args)}")
    t0 = time.perf_counter()
    done = subprocess.run([exe, *args], cwd=cwd, capture_output=True, text=True)
    wall = time.perf_counter() - t0
    return {
        "command": "jaxbearing " + " ".join(args),
        "exit_status": done.returncode,
        "wall_s": wall,
        "stdout_tail": done.stdout[-2000:],
        "stderr_tail": done.stderr[-2000:],
    }


def main(quick: bool = False) -> dict:
    work = Path(tempfile.mkdtemp(prefix="your-own-bearing-"))
    steps = [
        _run(
            ["config", "new", "--series", "02", "--bore-mm", "70", "--type", "NU", "--out", "nu214.toml"],
            work,
        )
    ]
    if quick:
        text = (work / "nu214.toml").read_text()
        (work / "nu214.toml").write_text(text.replace("num_slices = 31", "num_slices = 11"))
    steps.append(_run(["config", "check", "nu214.toml"], work))
    steps.append(_run(["zone", "--config", "nu214.toml"], work))
    sim = ["simulate", "--config", "nu214.toml", "--end", "arc", "--no-progress", "--out", "run"]
    if quick:
        sim += ["--window-revs", "2"]
    steps.append(_run(sim, work))
    summary = json.loads((work / "run" / "summary.json").read_text())
    run = {
        key: summary.get(key)
        for key in (
            "status",
            "settled",
            "settle_time_ms",
            "window_ms",
            "window_revs",
            "num_steps",
            "wall_time_s",
            "compile_time_s",
            "cage_speed_rpm",
            "kinematic_cage_speed_rpm",
            "cage_slip",
        )
    }
    run["flange_pv_mean_Pa_m_s"] = summary["flange_pv_Pa_m_s"]["mean"]
    run["contact_height_mean_m"] = summary["contact_height_m"]["mean"]
    config = (work / "nu214.toml").read_text()
    result = {
        "quick": quick,
        "steps": steps,
        "run": run,
        "config_toml": config,
        "machine": _common.machine_info(),
    }
    rows = [[s["command"], s["exit_status"], s["wall_s"]] for s in steps]
    result["table"] = _common.format_table(
        "Your own bearing: NU 214 (02 series, bore 70 mm)", ["command", "exit", "wall s"], rows
    )
    print(result["table"])
    _common.write_json(NAME + ("_quick" if quick else ""), result)
    shutil.rmtree(work, ignore_errors=True)
    return result


if __name__ == "__main__":
    main(quick="--quick" in sys.argv)
