"""The numbers the steady-running core must keep when it is restructured: a settled run from the
skid start with the settling verdict, a settled 2-case x 2-seed ensemble, the steady design
metrics, one frozen-load gradient and one iteration of the steady design search, all at reduced
size (11 slices per raceway, 2-revolution windows). `python tests/steady_core_reference.py`
writes `tests/data/steady_core_reference.json` with the setting that produced it (CPU, XLA
flags, package versions); `tests/test_same_numbers.py` checks that the code gives them again."""

from __future__ import annotations

import dataclasses
import json
import os
import pathlib
import platform
import sys
import tempfile

import numpy as np

REFERENCE = pathlib.Path(__file__).parent / "data" / "steady_core_reference.json"


def setting() -> dict:
    """What the bits of a run depend on beyond the code: the CPU, the XLA flags, the versions."""
    import diffrax
    import equinox
    import jax
    import jaxlib

    cpu = platform.processor()
    try:
        for line in pathlib.Path("/proc/cpuinfo").read_text().splitlines():
            if line.startswith("model name"):
                cpu = line.split(":", 1)[1].strip()
                break
    except OSError:
        pass
    return {
        "cpu": cpu,
        "xla_flags": os.environ.get("XLA_FLAGS", "").strip(),
        "jax": jax.__version__,
        "jaxlib": jaxlib.__version__,
        "diffrax": diffrax.__version__,
        "equinox": equinox.__version__,
    }


def _estimate(block) -> list:
    """[value, ci95_low, ci95_high] of a summary block or an `Estimate` (None for NaN)."""
    d = block if isinstance(block, dict) else block.as_dict()
    return [d.get(k) for k in ("value", "ci95_low", "ci95_high")]


def compute() -> dict:
    import jaxbearing as jb
    import optimise
    from jaxbearing.design import frozen_load_gradient, steady_design_metrics
    from jaxbearing.flange import DesignVariables
    from jaxbearing.run import (
        SettleFixed,
        SteadySettings,
        simulate_steady,
        simulate_steady_points,
        summarise_steady,
    )
    from optimise import make_problem

    b = dataclasses.replace(jb.reference_bearing(), num_slices=11)
    op = jb.reference_operating_point()
    short = SteadySettings(settle=SettleFixed(0.005), window_revs=2, seeds=2)
    out = {}

    auto = summarise_steady(simulate_steady(b, op, SteadySettings(window_revs=2)))
    out["settled_auto"] = {
        "settle_time_ms": auto["settle_time_ms"],
        "num_steps": auto["num_steps"],
        "cage_speed_rpm": _estimate(auto["cage_speed_rpm"]),
        "flange_pv_mean": _estimate(auto["flange_pv_Pa_m_s"]["mean"]),
        "contact_radius_p99": _estimate(auto["contact_radius_m"]["p99"]),
    }

    op2 = dataclasses.replace(op, radial_load=np.asarray(2000.0))
    out["two_cases_two_seeds"] = [
        {
            "cage_speed_rpm": _estimate(s["cage_speed_rpm"]),
            "flange_pv_mean": _estimate(s["flange_pv_Pa_m_s"]["mean"]),
            "num_steps": s["num_steps"],
        }
        for s in map(summarise_steady, simulate_steady_points(b, [op, op2], short))
    ]

    design = DesignVariables.of(b)
    m = steady_design_metrics(b, op, design, short)
    out["design_metrics"] = {"objective": _estimate(m.objective), "mean_pv": _estimate(m.mean_pv)}
    g = frozen_load_gradient(b, op, design, m.sample_states[:2])
    out["frozen_load_gradient"] = {"value": float(g.value), "gradient": np.asarray(g.gradient).tolist()}

    problem = make_problem(b, op)
    # the corner constraint of the recording (the default then)
    settings = optimise.SteadySettings(
        seeds=2,
        window_revs=2,
        settle=0.005,
        workers=1,
        corner_constraint=optimise.CornerConstraint.PREDICTION,
    )
    with tempfile.TemporaryDirectory() as tmp:
        res = optimise.steady_search(
            problem, settings, directory=tmp, num_starts=1, num_iterations=1, verify=False
        )
    out["search_iteration"] = {
        key: np.asarray(getattr(res.history, key)).tolist()
        for key in ("x", "objective", "gradient", "margins")
    }
    return out


if __name__ == "__main__":
    import jax

    jax.config.update("jax_enable_x64", True)
    values = {"setting": setting(), **compute()}
    REFERENCE.write_text(json.dumps(values, indent=1) + "\n")
    print(json.dumps(values, indent=1), file=sys.stderr)
