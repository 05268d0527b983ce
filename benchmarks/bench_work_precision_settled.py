"""Work-precision of the dynamic solve in SETTLED running: do the flange statistics computed
with the default integrator agree with a tight reference solution within their confidence
intervals, and what do cheaper tolerance settings give? (`bench_work_precision` measures the
same on the start-up transient, [2, 8] ms from the quasi-static start; its statistics are
imported from there.)

Case: the reference bearing (`jaxbearing.reference_bearing()`) at its reference operating point
(20,000 rpm, 1000 N), seeds 0-3 of the initial scatter (`jaxbearing.Perturbation(seed=s)`).

Protocol.

1. Settled start states: per seed, the library's own settled run
   (`jaxbearing.run.simulate_steady`: skid start with its pre-start, settling detection over
   cage revolutions, then the smallest allowed window of 2 revolutions; default integrator, one
   seed at a time in this process), and its `SeedRun.final_state`, kept under `CACHE_DIR`
   (data-only `.npz`, `jaxbearing.io.save_tree`) so that a rerun does not repeat the settling.
2. From each seed's settled state, a window of W = `WINDOW_REVS` cage revolutions (W =
   revolutions x 2 pi / the settled cage speed, the mean over seeds of the last settled
   revolution's mean, rounded to whole samples; the same W for every seed) is integrated with
   every integrator below from the same state, sampling the flange quantities every `SAMPLE_DT`
   = 2 us (the same instants for every integrator; as the library does, the states are kept in
   the loop and the flange quantities evaluated after it, vmapped: `_histories`; SciPy's from
   its dense output, likewise). The continuation is that of
   `jaxbearing.run.solve_from` (`prepare_from`: scaled deviation state about the start's own
   orbit, accumulators at zero), with the step controller built here as `prepare_from` builds it
   (`step_controller(rtol, atol, raceway_normal_norm(y0_scaled, loosen))`), so that rtol, atol
   and the raceway-normal loosening are chosen per integrator; the library is not changed.
   Integrators (`VARIANTS`, each row's label says what it runs): the reference, Tsit5 at rtol
   1e-7, atol 1e-14 (1e-16 m), plain max norm; rows 0-5 at atol `PREVIOUS_ATOL` (1 pm, 1 nm/s,
   1 urad/s: what atol 1e-6 meant before the state's scales were chosen for the tolerances,
   `jaxbearing.dynamics.SCALED_UNITS`) and rows 6-8 at today's 1e-6 (10 nm, 10 um/s,
   0.01 rad/s): rtol and the raceway-normal loosening, and SciPy `solve_ivp(RK45)` on the same
   compiled field (`_common.FlatField`, `bench_work_precision.ScipyRunner`); the error norms
   (9-15), the step controller (16-24) and the rotations' loosening (25-27; row 26 is the
   library's default, row 14 the per-roller RMS default before it).
3. Statistics per run over the window (`bench_work_precision.window_statistics`): mean and p95
   PV over flange samples with normal force > 1 N, mean sliding speed, cage slip
   1 - mean(cage speed) / kinematic cage speed; per-seed 95 % half-widths from 8 batch means of
   the reference run (`confidence_halfwidths`), and each integrator's per-seed error in those
   half-widths (`errors`).
4. The dynamics are chaotic (tangents grow e-fold in 16-80 us; roller-flange impacts), so the
   trajectories of different integrators decorrelate within about 1 ms and per-seed
   differences are mostly sampling noise. The main comparison is therefore over seeds
   (`paired_over_seeds`): per integrator and statistic, the mean over seeds of (integrator -
   reference) with its 95 % Student-t interval (n - 1 = 3 degrees of freedom), beside the
   reference's ensemble mean with its Student-t 95 % half-width over seeds. An integrator
   "agrees within CI" when the paired difference's interval contains 0 AND |mean difference| is
   below the reference ensemble mean's half-width.
5. Cost: field evaluations per simulated ms (Tsit5: `_common.fsal_rk_evaluations`, 6 per step
   attempt + 1; SciPy: nfev), their ratio against the old and today's default, and wall time
   per simulated ms (compile excluded, the samples included for every integrator; single runs
   on a shared 2-core machine: the evaluation counts are the primary figure).

`--reuse-reference` takes the reference runs from the stored results made for the same case (the
reference is 12 of the 18 minutes). `--quick`: seed 0, a 0.5 ms window, reference at rtol 1e-5 (a
smoke test; seed 0's settling is shared with the full run through the cache). `--revs N`: the window
in cage revolutions (default 2). `--rows 0,6,9`: only those rows of `VARIANTS` (ratios against the
defaults among them), written to `bench_work_precision_settled_rows.json` (`--tag rotation`:
`..._rows_rotation.json`). `--seeds 4,5,6,7`: other seeds' settled states (cached on first use;
`_seeds4-5-6-7` added to the results name), to check a choice on seeds it was not made on.
`--design R_end,theta_f,Delta_bf` (mm, deg, mm): the reference bearing with that roller-end and
flange design (its own settled states and reference; `_design...` added to the results name), for
designs near their corner limit, which the design search visits. Results:
`results/bench_work_precision_settled.json`.
"""

from __future__ import annotations

import math
import sys
import tempfile
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))

import _common  # noqa: E402
from bench_work_precision import (  # noqa: E402
    PREVIOUS_ATOL,
    REF_ATOL,
    REF_RTOL,
    SAMPLE_DT,
    STATS,
    ScipyRunner,
    confidence_halfwidths,
    errors,
    rows_argument,
    solve_record,
    variant_row,
    window_statistics,
)

NAME = "bench_work_precision_settled"
#: `make bench` (run_all) time limit: the tight reference alone takes 12-20 minutes
FULL_TIMEOUT_S = 2400
SEEDS = (0, 1, 2, 3)
WINDOW_REVS = 2
QUICK_WINDOW = 0.5e-3  # [s]
QUICK_REF_RTOL = 1e-5
MAX_STEPS = 2_000_000
CACHE_DIR = Path(tempfile.gettempdir()) / "jaxbearing_bench_work_precision_settled"
#: the saved quantities the statistics need
SAVED = ("t", "flange_force", "flange_pv", "flange_sliding_speed", "cage_speed")
OLD_DEFAULT, PREVIOUS_DEFAULT, CURRENT_DEFAULT = "old default", "previous default", "default"
#: the default from 2026-11-24 to 2026-11-25 (max norm, atol 10 nm)
MAX_NORM_DEFAULT = "max-norm default"
#: the default on 2026-11-25 before the rotations' tolerances were loosened (row 14)
PER_ROLLER_DEFAULT = "per-roller RMS default"
#: the rows that the evaluation ratios are taken against: (key in the results, label's start)
BASES = (
    ("old_default", OLD_DEFAULT),
    ("max_norm_default", MAX_NORM_DEFAULT),
    ("current_default", CURRENT_DEFAULT),
)


#: the step controller's coefficients, in the order of a row's "controller"
CONTROLLER_KEYS = ("pcoeff", "icoeff", "safety", "factormax")


def _controller_label(c: tuple) -> str:
    return "P {:g} I {:g} safety {:g} growth <= {:g}".format(*c)


#: (label, kind, rtol, atol, raceway_loosen[, options]); kind "tsit5" (diffrax, max norm with the
#: raceway-normal tolerances `raceway_loosen` times looser), "tsit5_rms" (the same weights, RMS
#: norm), "tsit5_body_rms" (the largest of the rollers', cage's and inner ring's RMS) or "scipy"
#: (solve_ivp RK45, RMS norm); options (`variant_options`, `window_solve`): "controller" (the PID
#: controller's `CONTROLLER_KEYS`), "rotation_loosen", "flat"
VARIANTS = (
    (f"{OLD_DEFAULT}: Tsit5, max norm, rtol 1e-3, atol 1 pm", "tsit5", 1e-3, PREVIOUS_ATOL, 1.0),
    (
        f"{PREVIOUS_DEFAULT}: Tsit5, raceway-normal x100, rtol 1e-3, atol 1 pm",
        "tsit5",
        1e-3,
        PREVIOUS_ATOL,
        100.0,
    ),
    ("Tsit5, raceway-normal x100, rtol 1e-2, atol 1 pm", "tsit5", 1e-2, PREVIOUS_ATOL, 100.0),
    ("Tsit5, raceway-normal x100, rtol 3e-3, atol 1 pm", "tsit5", 3e-3, PREVIOUS_ATOL, 100.0),
    ("Tsit5, raceway-normal x100, rtol 3e-2, atol 1 pm", "tsit5", 3e-2, PREVIOUS_ATOL, 100.0),
    ("SciPy RK45 (same field, RMS), rtol 1e-3, atol 1 pm", "scipy", 1e-3, PREVIOUS_ATOL, 1.0),
    (f"{MAX_NORM_DEFAULT}: Tsit5, raceway-normal x100, rtol 1e-3, atol 10 nm", "tsit5", 1e-3, 1e-6, 100.0),
    ("Tsit5, raceway-normal x100, rtol 1e-2, atol 10 nm", "tsit5", 1e-2, 1e-6, 100.0),
    ("SciPy RK45 (same field, RMS), rtol 1e-3, atol 10 nm", "scipy", 1e-3, 1e-6, 1.0),
    ("Tsit5, RMS norm, raceway-normal x100, rtol 1e-3, atol 10 nm", "tsit5_rms", 1e-3, 1e-6, 100.0),
    ("Tsit5, RMS norm, raceway-normal x100, rtol 1e-2, atol 10 nm", "tsit5_rms", 1e-2, 1e-6, 100.0),
    ("Tsit5, RMS norm, raceway-normal x100, rtol 3e-3, atol 10 nm", "tsit5_rms", 3e-3, 1e-6, 100.0),
    ("Tsit5, RMS norm, raceway-normal x10, rtol 1e-3, atol 10 nm", "tsit5_rms", 1e-3, 1e-6, 10.0),
    ("Tsit5, RMS norm (plain), rtol 1e-3, atol 10 nm", "tsit5_rms", 1e-3, 1e-6, 1.0),
    (
        f"{PER_ROLLER_DEFAULT}: Tsit5, per-roller RMS norm, raceway-normal x10, rtol 1e-3, atol 10 nm",
        "tsit5_body_rms",
        1e-3,
        1e-6,
        10.0,
    ),
    (
        "Tsit5, per-roller RMS norm, raceway-normal x100, rtol 1e-3, atol 10 nm",
        "tsit5_body_rms",
        1e-3,
        1e-6,
        100.0,
    ),
    # the step controller (rows 16-24): the default's norm and tolerances, other (pcoeff,
    # icoeff, safety, factormax); the library's is (0.3, 0.4, 0.9, 10)
    *(
        (
            f"Tsit5, per-roller RMS x10, rtol 1e-3, atol 10 nm, controller {_controller_label(c)}",
            "tsit5_body_rms",
            1e-3,
            1e-6,
            10.0,
            {"controller": c},
        )
        for c in (
            (0.0, 1.0, 0.9, 10.0),
            (0.4, 0.3, 0.9, 10.0),
            (0.1, 0.3, 0.9, 10.0),
            (0.0, 0.7, 0.9, 10.0),
            (0.3, 0.4, 0.8, 10.0),
            (0.3, 0.4, 0.95, 10.0),
            (0.3, 0.4, 1.0, 10.0),
            (0.3, 0.4, 0.9, 2.0),
            (0.3, 0.4, 0.9, 1.5),
        )
    ),
    # rows 25-27: the rollers' orbital rate and angular velocity and the cage, which held the
    # step under the per-roller RMS (results/diagnose_step_control_body_rms.json), looser; x10 is
    # the library's default (`jaxbearing.run.ROTATION_LOOSEN`)
    *(
        (
            f"{CURRENT_DEFAULT + ': ' if r == 10 else ''}Tsit5, per-roller RMS x10, rotations x{r:g}, "
            "rtol 1e-3, atol 10 nm",
            "tsit5_body_rms",
            1e-3,
            1e-6,
            10.0,
            {"rotation_loosen": r},
        )
        for r in (3.0, 10.0, 100.0)
    ),
    # row 28: the default with diffrax on the `State` pytree, as before 2026-11-25 (the library
    # hands it the state as one vector, `jaxbearing.run._flat`)
    (
        "Tsit5, per-roller RMS x10, rotations x10, rtol 1e-3, atol 10 nm, State pytree",
        "tsit5_body_rms",
        1e-3,
        1e-6,
        10.0,
        {"rotation_loosen": 10.0, "flat": False},
    ),
)
#: the error norm's kind (`RacewayNormalNorm.kind`) of each Tsit5 kind of `VARIANTS`
NORM_OF_KIND = {"tsit5": "max", "tsit5_rms": "rms", "tsit5_body_rms": "body_rms"}


# -- settled start states ----------------------------------------------------------------------
def settled_start(bearing, op, seed: int, design: tuple | None = None) -> dict:
    """Seed `seed`'s settled state (`SeedRun.final_state`) and how it was obtained, from the
    cache or from `simulate_steady` (2 window revolutions, one process). `design`: the
    `--design` triple the bearing was built with (part of the cache key), None for the
    reference bearing."""
    import jaxbearing as jb
    from jaxbearing.run import simulate_steady

    rpm, load = float(jb.rad_s_to_rpm(op.inner_speed)), float(op.radial_load)
    stem = "reference" if design is None else "design" + design_label(design)
    path = CACHE_DIR / f"{stem}_{rpm:.0f}rpm_{load:.0f}N_seed{seed}.npz"
    from jaxbearing.io import load_tree, save_tree

    if path.exists():
        out = load_tree(path, what="settled state")
        out["info"]["cached"] = True
        return out
    _common.log(f"{NAME}: settling seed {seed} (simulate_steady, skid start)")
    res = simulate_steady(bearing, op, seeds=1, perturbation=jb.Perturbation(seed=seed), window_revs=2)
    run = res.runs[0]
    if run.status != "ok":
        raise RuntimeError(f"the settled run of seed {seed} failed: {run.status}")
    info = {
        "settled": bool(run.settled),
        "settle_time_ms": 1e3 * run.settle_time,
        "end_time_ms": 1e3 * run.revolution_ends[-1],
        "last_revolution_cage_speed_rpm": run.revolution_speeds_rpm[-1],
        "num_steps": int(run.num_steps),
        "wall_s": res.wall_time_s,
        "compile_s": res.compile_time_s,
    }
    out = {"state": run.final_state, "info": info}
    save_tree(path, out)
    out["info"]["cached"] = False
    return out


# -- integrators -----------------------------------------------------------------------------
def window_solve(
    params,
    start,
    duration,
    rtol,
    atol,
    loosen,
    controller=None,
    rotation_loosen=1.0,
    *,
    num_saves: int,
    norm: str = "max",
    flat: bool | None = None,
):
    """Tsit5 from the physical state `start` over [0, duration] as `solve_from` integrates, with
    the error norm's raceway-normal loosening `loosen` chosen here: (samples of `SAVED` at
    `num_saves` equally spaced instants including both ends, result code, step attempts,
    rejected steps). `norm` (static): the norm's kind over the weighted components
    (`RacewayNormalNorm.kind`). `controller`: the step controller's (pcoeff, icoeff, safety,
    factormax), default the library's (`library_controller`). `rotation_loosen`: the rollers'
    orbital rate and angular velocity and the cage's coordinates that much looser
    (`raceway_normal_weights`). `flat` (static): the state as one vector (None: the library's
    choice, `_flat`), False: diffrax on the `State` pytree as before 2026-11-25. jit-able."""
    import diffrax
    import jax.numpy as jnp

    from jaxbearing.run import checks_without_host_callbacks, prepare_from, result_code, scaled_diffeqsolve
    from jaxbearing.run._simulate import _histories, _saved_state
    from jaxbearing.run._step_control import raceway_normal_norm, step_controller

    _, args, y0_scaled, _ = prepare_from(params, start, rtol, atol)
    coefficients = dict(zip(CONTROLLER_KEYS, library_controller() if controller is None else controller))
    controller = step_controller(
        rtol, atol, raceway_normal_norm(y0_scaled, loosen, norm, rotation_loosen), **coefficients
    )
    # as the library saves (`solve_from`): the states in the loop, the samples after it
    saveat = diffrax.SaveAt(ts=jnp.linspace(0.0, duration, num_saves), fn=_saved_state)
    with checks_without_host_callbacks():
        sol = scaled_diffeqsolve(
            y0_scaled, args, duration, saveat, controller, MAX_STEPS, None, False, "tsit5", flat=flat
        )
    hist = {k: v for k, v in _histories(sol.ts, sol.ys, args).items() if k in SAVED}
    return hist, result_code(sol.result), sol.stats["num_steps"], sol.stats["num_rejected_steps"]


def library_controller() -> tuple:
    """The library's step controller: (pcoeff, icoeff, safety, factormax)."""
    from jaxbearing.run import _step_control as c

    return (c.PID_PCOEFF, c.PID_ICOEFF, c.PID_SAFETY, c.PID_FACTORMAX)


def variant_options(options: dict | None = None) -> dict:
    """A row's options (`VARIANTS`) with the defaults filled in: the library's controller, the
    rotations not loosened, the state as the library hands it to diffrax ("flat": None)."""
    return {"controller": library_controller(), "rotation_loosen": 1.0, "flat": None, **(options or {})}


def compile_window_solve(params, start, num_saves: int, norm: str = "max", flat: bool | None = None):
    """`window_solve` compiled for (params, start, duration, rtol, atol, loosen, controller,
    rotation_loosen): one program per norm kind (and `flat`) serves every seed, tolerance,
    loosening and controller."""
    import jax.numpy as jnp

    def run(p, s, d, r, a, loosen, c, rotation):
        return window_solve(
            p, s, d, r, a, loosen, tuple(c), rotation, num_saves=num_saves, norm=norm, flat=flat
        )

    f = jnp.asarray
    example = (f(1e-3), f(1e-3), f(1e-6), f(1.0), f(library_controller()), f(1.0))
    return _common.compile_jit(run, params, start, *example)


def run_tsit5(
    compiled, params, start, duration, rtol, atol, loosen, controller=None, rotation_loosen=1.0
) -> dict:
    import jax.numpy as jnp

    f = jnp.asarray
    controller = f(controller or library_controller())
    wall, out = _common.time_once(
        lambda: compiled(
            params, start, f(duration), f(rtol), f(atol), f(loosen), controller, f(rotation_loosen)
        )
    )
    hist, code, steps, rejected = out
    return solve_record(wall, code, steps, rejected, hist)


def run_scipy(runner: ScipyRunner, params, start, duration, num_saves, rtol, atol) -> dict:
    """SciPy RK45 from the physical state `start` on the compiled flat field of `runner`, with
    the continuation's scaling and arguments (`prepare_from`), ravelled as `runner`'s field; the
    samples are part of the run, as in the Tsit5 rows (`window_solve`) and the library."""
    import numpy as np
    from jax.flatten_util import ravel_pytree

    from jaxbearing.run import prepare_from

    _, args, y0_scaled, _ = prepare_from(params, start, rtol, atol)
    y0, args_flat = (np.asarray(ravel_pytree(x)[0]) for x in (y0_scaled, args))
    if y0.size != runner.field0.size or args_flat.size != runner.field0.args_flat.size:
        raise RuntimeError("the continuation's state or arguments do not ravel like the flat field's")
    return runner.run_from(y0, args_flat, duration, num_saves, rtol, atol)


# -- statistics over seeds ---------------------------------------------------------------------
def paired_over_seeds(values, reference) -> dict:
    """Paired comparison over seeds (module docstring, 4): the reference's ensemble mean with its
    95 % Student-t interval, the mean of (values - reference) with its 95 % Student-t interval,
    and whether they agree (difference interval contains 0 and |mean difference| < the
    reference's half-width; None with fewer than two seeds)."""
    import numpy as np

    from jaxbearing.run import student_t_interval

    x, r = np.asarray(values, float), np.asarray(reference, float)
    ref, diff = student_t_interval(r), student_t_interval(x - r)
    out = {
        "reference": {**ref.as_dict(), "half_width": _finite(ref.half_width)},
        "difference": {**diff.as_dict(), "half_width": _finite(diff.half_width)},
        "agrees": None,
    }
    if diff.n >= 2 and ref.n >= 2:
        out["agrees"] = bool(diff.ci95_low <= 0.0 <= diff.ci95_high and abs(diff.value) < ref.half_width)
    return out


def _finite(x: float):
    return float(x) if math.isfinite(x) else None


# -- the benchmark -----------------------------------------------------------------------------
def stored_reference(case: dict, names: tuple = (NAME,)) -> dict | None:
    """The reference runs of the stored results (`names` in results/, the first that fits) when
    they were made for `case` (seeds, window, samples, reference tolerances): `--reuse-reference`
    runs only the integrators (the reference is 12 of the study's 18 minutes)."""
    import json

    keys = ("seeds", "window_s", "num_saves", "inner_speed_rpm", "radial_load_N", "design", "reference")
    for name in names:
        path = _common.RESULTS_DIR / f"{name}.json"
        old = json.loads(path.read_text()) if path.exists() else {"quick": True}
        if not old.get("quick") and all(old["case"].get(k) == case[k] for k in keys):
            return old["reference"]
    return None


def output_name(only: tuple | None, seeds: tuple, tag: str | None = None, design: tuple | None = None) -> str:
    """Results name: `NAME`, `_rows` with --rows, `_{tag}` with --tag, `_seeds4-7` (say) with
    other seeds than `SEEDS`, `_design94.31-1.839-0.15` (say) with --design."""
    return (
        NAME
        + ("" if only is None else "_rows")
        + ("" if not tag else f"_{tag}")
        + ("" if tuple(seeds) == SEEDS else "_seeds" + "-".join(str(s) for s in seeds))
        + ("" if design is None else "_design" + design_label(design))
    )


def design_label(design: tuple) -> str:
    """`94.31-1.839-0.15` for (R_end mm, theta_f deg, Delta_bf mm) = (94.31, 1.839, 0.15)."""
    return "-".join(f"{v:.4g}" for v in design)


#: the configuration keys of `--design`'s three numbers, in order (engineering units; their valid
#: ranges are the schema's, `jaxbearing.io`, checked by `Config.replace`)
DESIGN_KEYS = ("roller.end_radius_mm", "flange.layback_angle_deg", "flange.axial_clearance_mm")


def design_argument(argv: list) -> tuple | None:
    """(R_end mm, theta_f deg, Delta_bf mm) of `--design 94.31,1.839,0.15`, None without it;
    anything else ends the program with one line naming the option and its value (and, for a
    number out of range, the configuration key and its valid range)."""
    import jaxbearing as jb

    text = _common.option_value(argv, "--design")
    if text is None:
        return None
    try:
        values = tuple(float(p) for p in text.split(","))
    except ValueError:
        values = ()
    if len(values) != 3:
        raise SystemExit(f"--design = {text!r}: three numbers R_end,theta_f,Delta_bf in mm, deg, mm")
    try:
        design_bearing(values)
    except jb.ConfigError as err:
        raise SystemExit(f"--design = {text!r}: {err}") from None
    return values


def design_bearing(design: tuple | None):
    """The reference bearing, with `--design`'s R_end [mm], theta_f [deg], Delta_bf [mm] when
    given: the reference configuration with `DESIGN_KEYS` replaced (validated there)."""
    import jaxbearing as jb

    config = jb.reference_config()
    if design is not None:
        config = config.replace(dict(zip(DESIGN_KEYS, design)))
    return config.bearing()


def tag_argument(argv: list) -> str | None:
    """`--tag NAME` (letters, digits, '-' and '_'): a results name of its own, so that a study
    does not overwrite the rows quoted from another."""
    tag = _common.option_value(argv, "--tag")
    if tag is not None and not (tag and all(c.isalnum() or c in "-_" for c in tag)):
        raise SystemExit(f"--tag = {tag!r}: letters, digits, '-' or '_', e.g. rotation")
    return tag


def main(
    quick: bool = False,
    window_revs: int = WINDOW_REVS,
    reuse_reference: bool = False,
    only: tuple | None = None,
    seeds: tuple = SEEDS,
    tag: str | None = None,
    design: tuple | None = None,
) -> dict:
    import jax
    import jax.numpy as jnp
    import numpy as np

    import jaxbearing as jb
    from jaxbearing.dynamics import SCALED_UNITS, Functionals, Params

    started = time.perf_counter()
    name = output_name(only, seeds, tag, design)
    seeds = seeds[:1] if quick else tuple(seeds)
    ref_rtol = QUICK_REF_RTOL if quick else REF_RTOL
    bearing, op = design_bearing(design), jb.reference_operating_point()
    jb.validate_bearing(bearing, op)
    params = Params(bearing=bearing, operating=op, functionals=Functionals())
    omega_kin = float(jb.kinematic_cage_speed(bearing, op))

    t_settle = time.perf_counter()
    settled = {s: settled_start(bearing, op, s, design) for s in seeds}
    settle_wall = time.perf_counter() - t_settle
    starts = {s: jax.tree_util.tree_map(jnp.asarray, v["state"]) for s, v in settled.items()}
    rpm = float(np.mean([v["info"]["last_revolution_cage_speed_rpm"] for v in settled.values()]))
    window = QUICK_WINDOW if quick else window_revs * 60.0 / rpm
    num_saves = int(round(window / SAMPLE_DT)) + 1
    window = (num_saves - 1) * SAMPLE_DT
    ms = window * 1e3

    _common.log(f"{NAME}: compiling the window solve, {num_saves} samples over {ms:g} ms")
    variants = list(VARIANTS) if only is None else [VARIANTS[i] for i in only]
    compiled, compile_s = {}, {}
    # one program per (norm, flat); ("max", None): the reference
    programs = {
        (NORM_OF_KIND[v[1]], variant_options(v[5] if len(v) > 5 else None)["flat"])
        for v in variants
        if v[1] != "scipy"
    } | {("max", None)}
    for norm, flat in sorted(programs, key=str):
        key = f"window_solve_{norm}" + ("" if flat is None else f"_flat_{flat}")
        compiled[norm, flat], compile_s[key] = compile_window_solve(
            params, starts[seeds[0]], num_saves, norm, flat
        )
    scipy_runner = None
    if any(v[1] == "scipy" for v in variants):
        scipy_runner = ScipyRunner(bearing, op)
        compile_s["scipy_field"] = scipy_runner.compile_s

    def run(kind, seed, rtol, atol, loosen, options=None):
        o = variant_options(options)
        if kind == "scipy":
            r = run_scipy(scipy_runner, params, starts[seed], window, num_saves, rtol, atol)
        else:
            program = compiled[NORM_OF_KIND[kind], o["flat"]]
            r = run_tsit5(
                program,
                params,
                starts[seed],
                window,
                rtol,
                atol,
                loosen,
                o["controller"],
                o["rotation_loosen"],
            )
        hist = r.pop("hist")
        r["statistics"] = window_statistics(hist, 0.0, omega_kin)
        r["evaluations_per_ms"] = r["evaluations"] / ms
        r["wall_s_per_ms"] = r["wall_s"] / ms
        return r, hist

    case = {
        "bearing": "reference_bearing() (26 rollers, 31 slices, arc ends)"
        + ("" if design is None else ", with --design R_end, theta_f, Delta_bf"),
        "design": None
        if design is None
        else dict(zip(("end_radius_mm", "layback_angle_deg", "axial_clearance_mm"), design)),
        "inner_speed_rpm": float(jb.rad_s_to_rpm(op.inner_speed)),
        "radial_load_N": float(op.radial_load),
        "seeds": list(seeds),
        "window_revs": None if quick else window_revs,
        "window_s": window,
        "settled_cage_speed_rpm": rpm,
        "kinematic_cage_speed_rpm": float(jb.rad_s_to_rpm(omega_kin)),
        "sample_dt_s": SAMPLE_DT,
        "num_saves": num_saves,
        "reference": {
            "rtol": ref_rtol,
            "atol": REF_ATOL,
            "atol_length_m": REF_ATOL * SCALED_UNITS[0],
            "method": "Tsit5, max norm (loosen 1)",
        },
        "agreement": "paired difference's 95 % Student-t interval over seeds contains 0 and "
        "|mean difference| < the reference ensemble mean's 95 % Student-t half-width over seeds",
        "note": "every integrator starts from the same settled state per seed (simulate_steady's "
        "final_state); per-seed CI from 8 batch means of the reference over the window; cage slip "
        "errors are absolute",
    }
    names = (NAME, name, output_name(None, seeds, design=design))
    reference = (stored_reference(case, names) if reuse_reference else None) or {}
    if reference:
        _common.log(f"{NAME}: reference runs from the stored results (--reuse-reference)")
    for seed in seeds:
        if str(seed) in reference:
            continue
        _common.log(f"{NAME}: reference (rtol {ref_rtol:g}), seed {seed}")
        r, hist = run("tsit5", seed, ref_rtol, REF_ATOL, 1.0)
        if not r["ok"]:
            raise RuntimeError(f"the reference solve failed (seed {seed})")
        r["ci_halfwidth"] = confidence_halfwidths(hist, 0.0, omega_kin)
        reference[str(seed)] = r
        _common.log(f"  {r['evaluations_per_ms']:.0f} evaluations/ms, {r['wall_s_per_ms']:.2f} s/ms")
    ref_values = {s: [reference[str(seed)]["statistics"][s] for seed in seeds] for s in STATS}

    rows = []
    for label, kind, rtol, atol, loosen, *rest in variants:
        options = variant_options(rest[0] if rest else None)
        per_seed = {}
        for seed in seeds:
            _common.log(f"{NAME}: {label}, seed {seed}")
            r, _ = run(kind, seed, rtol, atol, loosen, options)
            ref = reference[str(seed)]
            r["errors"] = errors(r["statistics"], ref["statistics"], ref["ci_halfwidth"])
            per_seed[str(seed)] = r
        runs = list(per_seed.values())
        rows.append(
            {
                **variant_row(label, kind, rtol, atol, loosen, per_seed),
                "controller": dict(zip(CONTROLLER_KEYS, options["controller"])),
                "rotation_loosen": options["rotation_loosen"],
                "flat": options["flat"],
                "over_seeds": {
                    s: paired_over_seeds([x["statistics"][s] for x in runs], ref_values[s]) for s in STATS
                },
            }
        )
        rows[-1]["agrees_all"] = all(rows[-1]["over_seeds"][s]["agrees"] for s in STATS)
    for key, label in BASES:
        base = next((r for r in rows if r["label"].startswith(label + ":")), None)
        for row in rows:  # with --rows, only against the defaults that were run
            if base is not None:
                row[f"evaluation_ratio_vs_{key}"] = base["evaluations_per_ms"] / row["evaluations_per_ms"]
    result = {
        "benchmark": NAME,
        "quick": quick,
        "case": case,
        "settled_starts": {str(s): v["info"] for s, v in settled.items()},
        "settle_wall_s": settle_wall,
        "compile_s": compile_s,
        "reference": reference,
        "reference_over_seeds": {
            s: paired_over_seeds(ref_values[s], ref_values[s])["reference"] for s in STATS
        },
        "variants": rows,
        "benchmark_wall_s": time.perf_counter() - started,
    }
    result["table"] = _table(result)
    print(result["table"])
    _common.write_json(name, result)
    return result


#: (statistic, display name, factor to display units)
_DISPLAY = {
    "mean_pv": ("mean PV MPa m/s", 1e-6),
    "p95_pv": ("p95 PV MPa m/s", 1e-6),
    "mean_sliding_speed": ("mean u m/s", 1.0),
    "cage_slip": ("slip %", 100.0),
}


def _pm(est: dict, factor: float) -> str:
    v, hw = est["value"], est["half_width"]
    return "-" if v is None else f"{v * factor:.4g}" + ("" if hw is None else f" +- {hw * factor:.3g}")


def _table(r: dict) -> str:
    import numpy as np

    c, design = r["case"], r["case"].get("design")
    refs = r["reference"].values()
    mean_ref = [float(np.mean([x[k] for x in refs])) for k in ("evaluations_per_ms", "wall_s_per_ms")]
    cost_rows = [[f"reference rtol {c['reference']['rtol']:g}", mean_ref[0], None, None, None, mean_ref[1]]]
    for v in r["variants"]:
        ratios = (v.get(f"evaluation_ratio_vs_{key}", math.nan) for key, _ in BASES)
        agree = v["agrees_all"] if len(c["seeds"]) > 1 else None
        cost_rows.append(
            [v["label"], v["evaluations_per_ms"], *ratios, v["wall_s_per_ms"], v["max_error_in_ci"], agree]
        )
    bearing = "reference bearing" + (
        ""
        if not design
        else f" with R_end {design['end_radius_mm']:g} mm, theta_f {design['layback_angle_deg']:g} deg, "
        f"Delta_bf {design['axial_clearance_mm']:g} mm,"
    )
    cost = _common.format_table(
        f"Work-precision in settled running: {bearing} {c['inner_speed_rpm']:.0f} rpm, {c['radial_load_N']:.0f} "
        f"N; window {c['window_s'] * 1e3:.3g} ms from each seed's settled state, seeds {c['seeds']}",
        ["integrator", "evals/ms", *(f"x fewer vs {w}" for w in ("old", "max-norm", "default"))]
        + ["wall s/ms", "max err/CI", "agree"],
        [row + [None] * (8 - len(row)) for row in cost_rows],
    )
    flag = {True: " yes", False: " NO", None: ""}
    agree_rows = [
        ["reference (ensemble)", *(_pm(r["reference_over_seeds"][s], _DISPLAY[s][1]) for s in STATS)]
    ]
    for v in r["variants"]:
        o = v["over_seeds"]
        agree_rows.append(
            [v["label"], *(_pm(o[s]["difference"], _DISPLAY[s][1]) + flag[o[s]["agrees"]] for s in STATS)]
        )
    agree = _common.format_table(
        "Reference ensemble mean +- 95 % half-width over seeds; per integrator: mean paired difference "
        "(integrator - reference) +- 95 % half-width over seeds, and whether it agrees",
        ["integrator", *(_DISPLAY[s][0] for s in STATS)],
        agree_rows,
    )
    return cost + "\n\n" + agree


def seeds_argument(argv: list) -> tuple:
    """The seeds of `--seeds 4,5,6,7` (`SEEDS` without it); anything but two or more distinct
    non-negative integers ends the program with one line naming the option and its value."""
    text = _common.option_value(argv, "--seeds")
    if text is None:
        return SEEDS
    parts = text.split(",")
    if not all(p.strip().isdigit() for p in parts) or len(set(parts)) < 2:
        raise SystemExit(f"--seeds = {text!r}: two or more distinct non-negative integers, e.g. 4,5,6,7")
    return tuple(int(p) for p in parts)


if __name__ == "__main__":
    revs = int(sys.argv[sys.argv.index("--revs") + 1]) if "--revs" in sys.argv else WINDOW_REVS
    main(
        quick="--quick" in sys.argv,
        window_revs=revs,
        reuse_reference="--reuse-reference" in sys.argv,
        only=rows_argument(sys.argv, len(VARIANTS)),
        seeds=seeds_argument(sys.argv),
        tag=tag_argument(sys.argv),
        design=design_argument(sys.argv),
    )
