"""Which coordinates hold the step in settled running (issue 12, item 2): field evaluations per
simulated ms of Tsit5 at rtol 1e-3, atol 1e-6 when the error norm's weights are loosened by
groups of state components.

From seed 0's settled state of `bench_work_precision_settled` (`settled_start`, cached), 2 ms are
integrated as `jaxbearing.run.solve_from` does, with the weights of
`jaxbearing.run._step_control.raceway_normal_weights` further divided by `LOOSEN` = 100 on groups
of the rollers' components, the cage and the inner ring. The error norm: `--norm body_rms`
(per-body RMS, raceway-normal coordinates 10x looser: the library's default on 2026-11-25
before the rotations' tolerances were loosened, which this study led to; results
`diagnose_step_control_body_rms.json`) or `--norm max` (the max-norm default of 2026-11-24:
max norm, raceway-normal 100x looser; `diagnose_step_control.json`, the default of this script):

* the norm as it is (nothing more loosened), and one group at a time loosened;
* everything loosened, and everything but one group: the evaluations with only that group at
  the default tolerance show how hard it alone holds the step;
* for comparison, the plain rtol of 1e-2, 3e-2 and 1e-1 (raceway-normal x100).

Evaluation counts do not depend on the machine's load (`_common.fsal_rk_evaluations`).

    python benchmarks/studies/diagnose_step_control.py [--norm body_rms]
"""

from __future__ import annotations

import sys
from pathlib import Path

sys.path[:0] = [str(Path(__file__).resolve().parent), str(Path(__file__).resolve().parents[1])]

import _common  # noqa: E402

NAME = "diagnose_step_control"
DURATION = 2e-3  # [s]
LOOSEN = 100.0
ROLLER_GROUPS = ("axial", "azimuth", "axis", "axial_velocity", "azimuth_rate", "angular_velocity")
#: the rollers' raceway-normal coordinates (radial position and velocity), loosened together
RADIAL = ("radial", "radial_velocity")
GROUPS = ROLLER_GROUPS + ("radial", "cage", "inner_ring")
#: error norm kind: raceway-normal loosening of the norm's default weights
RACEWAY_LOOSEN = {"max": 100.0, "body_rms": 10.0}


def weights(y0_scaled, loosened: dict, raceway_loosen: float):
    """The norm's weights (raceway-normal coordinates `raceway_loosen` looser) with each group of
    `loosened` ({group: factor}) divided by its factor."""
    import equinox as eqx
    import jax

    from jaxbearing.run._step_control import raceway_normal_weights

    w = raceway_normal_weights(y0_scaled, raceway_loosen)
    names = ROLLER_GROUPS + RADIAL
    factor = {**{g: loosened[g] for g in ROLLER_GROUPS}, **dict.fromkeys(RADIAL, loosened["radial"])}
    rollers = eqx.tree_at(
        lambda r: [getattr(r, g) for g in names],
        w.rollers,
        [getattr(w.rollers, g) / factor[g] for g in names],
    )
    cage = jax.tree_util.tree_map(lambda x: x / loosened["cage"], w.cage)
    ring = jax.tree_util.tree_map(lambda x: x / loosened["inner_ring"], w.inner_ring)
    return eqx.tree_at(lambda s: (s.rollers, s.cage, s.inner_ring), w, (rollers, cage, ring))


def step_counts(params, start, rtol, loosened: dict, norm: str = "max"):
    """(result code, step attempts, rejected steps) of Tsit5 over DURATION from `start`, error
    norm `norm` (static). jit-able."""
    import diffrax

    from jaxbearing.run import checks_without_host_callbacks, prepare_from, result_code, scaled_diffeqsolve
    from jaxbearing.run._step_control import RacewayNormalNorm, step_controller

    _, args, y0, _ = prepare_from(params, start, rtol, 1e-6)
    w = weights(y0, loosened, RACEWAY_LOOSEN[norm])
    controller = step_controller(rtol, 1e-6, RacewayNormalNorm(weights=w, kind=norm))
    saveat = diffrax.SaveAt(t1=True, fn=lambda t, y, a: a.scaling.unscale(t, y).cage.speed)
    with checks_without_host_callbacks():
        sol = scaled_diffeqsolve(y0, args, DURATION, saveat, controller, 2_000_000, None, False, "tsit5")
    return result_code(sol.result), sol.stats["num_steps"], sol.stats["num_rejected_steps"]


def cases(norm: str = "max") -> list[tuple[str, float, dict]]:
    """(label, rtol, {group: loosening}) of the module docstring."""
    none = dict.fromkeys(GROUPS, 1.0)
    every = dict.fromkeys(GROUPS, LOOSEN)
    rows = [(f"{norm} norm (raceway-normal x{RACEWAY_LOOSEN[norm]:g}), rtol 1e-3", 1e-3, none)]
    rows += [(f"{g} x{LOOSEN:g}", 1e-3, {**none, g: LOOSEN}) for g in GROUPS]
    rows += [(f"all groups x{LOOSEN:g}", 1e-3, every)]
    rows += [(f"all groups x{LOOSEN:g} but {g}", 1e-3, {**every, g: 1.0}) for g in GROUPS]
    rows += [(f"default norm, rtol {r:g}", r, none) for r in (1e-2, 3e-2, 1e-1)]
    return rows


def main(norm: str = "max") -> dict:
    import jax
    import jax.numpy as jnp
    from bench_work_precision_settled import settled_start

    import jaxbearing as jb
    from jaxbearing.dynamics import Functionals, Params

    bearing, op = jb.reference_bearing(), jb.reference_operating_point()
    params = Params(bearing=bearing, operating=op, functionals=Functionals())
    start = jax.tree_util.tree_map(jnp.asarray, settled_start(bearing, op, 0)["state"])
    run = jax.jit(step_counts, static_argnames="norm")
    rows = []
    for label, rtol, loosened in cases(norm):
        code, attempts, rejected = run(
            params, start, jnp.asarray(rtol), {k: jnp.asarray(v) for k, v in loosened.items()}, norm=norm
        )
        attempts = int(attempts)
        evals = _common.fsal_rk_evaluations(attempts) / (DURATION * 1e3)
        rows.append(
            {
                "label": label,
                "rtol": rtol,
                "loosened": loosened,
                "ok": int(code) == 0,
                "step_attempts": attempts,
                "rejected_steps": int(rejected),
                "evaluations_per_ms": evals,
                "mean_attempt_us": DURATION / attempts * 1e6,
            }
        )
        _common.log(f"{NAME}: {label}: {evals:.0f} evaluations/ms")
    default = rows[0]["evaluations_per_ms"]
    for row in rows:
        row["fewer_than_default"] = default / row["evaluations_per_ms"]
    result = {
        "benchmark": NAME,
        "case": "reference bearing, 20,000 rpm, 1000 N; seed 0's settled state; Tsit5 over 2 ms",
        "norm": norm,
        "raceway_loosen": RACEWAY_LOOSEN[norm],
        "rows": rows,
    }
    result["table"] = _common.format_table(
        "Which coordinates hold the step (Tsit5, settled state, 2 ms)",
        ["error norm", "evals/ms", "x fewer than default", "mean attempt us", "rejected"],
        [
            [
                r["label"],
                r["evaluations_per_ms"],
                r["fewer_than_default"],
                r["mean_attempt_us"],
                r["rejected_steps"],
            ]
            for r in rows
        ],
    )
    print(result["table"])
    _common.write_json(NAME if norm == "max" else f"{NAME}_{norm}", result)
    return result


if __name__ == "__main__":
    kind = _common.option_value(sys.argv, "--norm")
    kind = "max" if kind is None else kind
    if kind not in RACEWAY_LOOSEN:
        raise SystemExit(f"--norm {kind}: not one of {sorted(RACEWAY_LOOSEN)}")
    main(kind)
