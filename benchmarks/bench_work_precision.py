"""Work-precision of the dynamic solve (issue 12, item 1): error of flange statistics against a
tight reference solution, versus field evaluations and wall time.

Case: the reference bearing at 20,000 rpm and 1000 N, seeded initial scatter
(`jaxbearing.Perturbation(seed=s)`, the same seeds for every integrator).

Window: the start-up transient (settled running: `bench_work_precision_settled`). Every run is
integrated over [0, T0 + W] from the quasi-static start and the statistics are taken over the
fixed window [T0, T0 + W] (full: T0 = 2 ms, W = 6 ms, seeds 0 and 1; quick: T0 = W = 1 ms,
seed 0), from samples every `SAMPLE_DT` = 2 us (the same instants for every integrator), and
compared with the reference's over the same window and seed.

Statistics (flange samples with normal force > 1 N, every roller and flange): mean and 95th
percentile of PV, mean sliding speed; cage slip 1 - mean(omega_c) / omega_c,kin over the window.
Confidence interval of each (95 %): batch means over 8 contiguous blocks of the window
(t-distribution, 7 degrees of freedom), of the reference run.

Reference: `jaxbearing.solve` with Tsit5, max norm, rtol 1e-7, atol 1e-14 (1e-16 m).

Integrators (`VARIANTS`, on the same compiled field and initial state; rows 0-12 at atol
`PREVIOUS_ATOL`, 1 pm: what atol 1e-6 meant before the state's scales were chosen for the
tolerances, `jaxbearing.dynamics.SCALED_UNITS`; rows 13-15 at today's 1e-6, 10 nm): `jaxbearing.solve`
with the max norm (the old default) and the raceway-normal tolerances loosened (`raceway_loosen`,
`jaxbearing.run._step_control`), with `optimistix.rms_norm` and with `solver="ros34pw2"` (the
Rosenbrock-W method, every roller's 12 x 12 Jacobian block implicit, `jaxbearing.run._rosenbrock`);
SciPy `solve_ivp(RK45)` (RMS norm) driving the compiled flat field (`_common.FlatField`).

`--imex` runs only the reference, the default Tsit5 rows and the Rosenbrock-W rows
(`IMEX_VARIANTS`) and writes `bench_work_precision_imex.json`. `--rows 0,3,13` runs the
reference and those rows of `VARIANTS` (ratios against the first) and writes
`bench_work_precision_rows.json`. `--corner`: flat ends with the corner radius instead of arc
ends (`with_flat_ends()`; "_corner" added to the results' name).

Reported per integrator and seed: step attempts, rejected steps, field evaluations (Tsit5:
6 attempts + 1, `_common.fsal_rk_evaluations`; SciPy: nfev; Rosenbrock-W: 4 attempts + 1, plus
one batched 12-JVP block Jacobian per attempt, counted as `jacobian_cost_in_evaluations`
field evaluations, measured by `jacobian_cost`), evaluations per simulated ms, wall
time (compile excluded; single runs, on a shared machine: read the evaluation counts first),
every statistic, its relative error and its error in units of the reference's CI half-width.
"""

from __future__ import annotations

import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))

import _common  # noqa: E402

NAME = "bench_work_precision"
#: `make bench` (run_all) time limit: the tight reference alone takes 12-20 minutes
FULL_TIMEOUT_S = 2400
SAMPLE_DT = 2e-6  # [s] spacing of the saved samples
CONTACT_THRESHOLD = 1.0  # [N] a flange sample counts as in contact above this force
NUM_BLOCKS = 8  # batch means for the confidence intervals
T_975_7DOF = 2.364624  # Student t quantile 0.975, 7 degrees of freedom
#: atol of the scaled state that means what atol 1e-6 meant before the state's scales were
#: chosen for the tolerances (1 pm, 1 nm/s, 1 urad/s; `jaxbearing.dynamics.SCALED_UNITS`:
#: the default atol 1e-6 is now 10 nm, 10 um/s, 0.01 rad/s). The rows below keep the physical
#: tolerances they were measured with.
PREVIOUS_ATOL = 1e-10
#: the tight reference: rtol 1e-7, atol 1e-16 m (1e-10 of the earlier 1-um units)
REF_RTOL, REF_ATOL = 1e-7, 1e-14
STATS = ("mean_pv", "p95_pv", "mean_sliding_speed", "cage_slip")

#: (label, kind, rtol, atol, raceway_loosen[, rotation_loosen]); kind: "solve" (max norm weighted
#: by raceway_loosen; row 13, x100, is solve's default), "rms" (solve with optimistix.rms_norm),
#: "scipy" (solve_ivp RK45), "ros" (ROS34PW2, max norm weighted by raceway_loosen), "default" (the
#: largest RMS of one body's coordinates weighted by raceway_loosen: the settled windows' norm);
#: the rotations' loosening (`solve(rotation_loosen=...)`) is 1 where absent
VARIANTS = (
    ("old default: Tsit5, max norm, rtol 1e-3", "solve", 1e-3, PREVIOUS_ATOL, 1.0),
    ("Tsit5, max norm, rtol 1e-2", "solve", 1e-2, PREVIOUS_ATOL, 1.0),
    ("Tsit5, raceway-normal tol x10, rtol 1e-3", "solve", 1e-3, PREVIOUS_ATOL, 10.0),
    ("Tsit5, raceway-normal tol x100, rtol 1e-3", "solve", 1e-3, PREVIOUS_ATOL, 100.0),
    ("Tsit5, raceway-normal tol x1000, rtol 1e-3", "solve", 1e-3, PREVIOUS_ATOL, 1000.0),
    ("Tsit5, raceway-normal tol x1e4, rtol 1e-3", "solve", 1e-3, PREVIOUS_ATOL, 1e4),
    ("Tsit5, raceway-normal tol x100, rtol 1e-2", "solve", 1e-2, PREVIOUS_ATOL, 100.0),
    ("Tsit5, raceway-normal tol x1e4, rtol 1e-2", "solve", 1e-2, PREVIOUS_ATOL, 1e4),
    ("Tsit5, RMS norm, rtol 1e-3", "rms", 1e-3, PREVIOUS_ATOL, 1.0),
    ("SciPy RK45 (same field, RMS), rtol 1e-3", "scipy", 1e-3, PREVIOUS_ATOL, 1.0),
    ("Rosenbrock-W ROS34PW2, raceway-normal tol x100, rtol 1e-3", "ros", 1e-3, PREVIOUS_ATOL, 100.0),
    ("Rosenbrock-W ROS34PW2, raceway-normal tol x100, rtol 1e-2", "ros", 1e-2, PREVIOUS_ATOL, 100.0),
    ("Rosenbrock-W ROS34PW2, raceway-normal tol x100, rtol 3e-2", "ros", 3e-2, PREVIOUS_ATOL, 100.0),
    ("max-norm default: Tsit5, raceway-normal tol x100, rtol 1e-3, atol 10 nm", "solve", 1e-3, 1e-6, 100.0),
    (
        "per-roller RMS default: Tsit5, per-roller RMS norm, raceway-normal tol x10, rtol 1e-3, atol 10 nm",
        "default",
        1e-3,
        1e-6,
        10.0,
    ),
    (
        "default: Tsit5, per-roller RMS norm, raceway-normal tol x10, rotations x10, rtol 1e-3, atol 10 nm",
        "default",
        1e-3,
        1e-6,
        10.0,
        10.0,
    ),
)
QUICK_VARIANTS = (0, 3, 5, 8, 9, 15)
#: `--imex`: the old and previous Tsit5 defaults (atol 1 pm), Tsit5 at rtol 1e-2, and the Rosenbrock-W rows
IMEX_VARIANTS = (0, 3, 6, 10, 11, 12)


def tsit5_stability_limit(eigenvalue: complex, h_max: float = 1e-4) -> float:
    """Largest step h [s] with |R(h lambda)| <= 1 on (0, h] for diffrax's Tsit5 tableau, where
    R(z) = 1 + z b^T (I - z A)^-1 1 is the stability function (bisection on a fine grid)."""
    import diffrax
    import numpy as np

    tab = diffrax.Tsit5().tableau
    n = len(tab.b_sol)
    a = np.zeros((n, n))
    for i, row in enumerate(tab.a_lower):
        a[i + 1, : i + 1] = np.asarray(row)
    b = np.asarray(tab.b_sol)

    def stable(h):
        z = h * eigenvalue
        return abs(1 + z * b @ np.linalg.solve(np.eye(n) - z * a, np.ones(n))) <= 1.0

    hs = np.linspace(h_max / 1e5, h_max, 100_000)
    ok = np.array([stable(h) for h in hs])
    return float(hs[np.argmin(ok) - 1]) if not ok.all() else h_max


# -- statistics --------------------------------------------------------------------------------
def window_statistics(hist: dict, t_start: float, omega_kin: float) -> dict:
    """Flange statistics over the samples with t >= t_start (module docstring)."""
    import numpy as np

    t = np.asarray(hist["t"])
    m = t >= t_start - 1e-12
    q = np.asarray(hist["flange_force"])[m]
    pv = np.asarray(hist["flange_pv"])[m]
    u = np.asarray(hist["flange_sliding_speed"])[m]
    cage = np.asarray(hist["cage_speed"])[m]
    c = q > CONTACT_THRESHOLD
    nan = float("nan")
    return {
        "mean_pv": float(pv[c].mean()) if c.any() else nan,
        "p95_pv": float(np.percentile(pv[c], 95)) if c.any() else nan,
        "mean_sliding_speed": float(u[c].mean()) if c.any() else nan,
        "cage_slip": float(1.0 - cage.mean() / omega_kin),
        "contact_samples": int(c.sum()),
    }


def confidence_halfwidths(hist: dict, t_start: float, omega_kin: float) -> dict:
    """95 % half-widths of every statistic from `NUM_BLOCKS` batch means over the window."""
    import numpy as np

    t = np.asarray(hist["t"])
    idx = np.flatnonzero(t >= t_start - 1e-12)
    blocks = np.array_split(idx, NUM_BLOCKS)
    per_block = [
        window_statistics({k: np.asarray(v)[b] for k, v in hist.items()}, t_start, omega_kin) for b in blocks
    ]
    out = {}
    for s in STATS:
        vals = np.array([b[s] for b in per_block], float)
        vals = vals[np.isfinite(vals)]
        out[s] = float(T_975_7DOF * vals.std(ddof=1) / np.sqrt(len(vals))) if len(vals) > 1 else float("nan")
    return out


def errors(stats: dict, ref: dict, ci: dict) -> dict:
    """Relative error (cage slip: absolute, in slip units) and error in CI half-widths."""
    rel, in_ci = {}, {}
    for s in STATS:
        d = abs(stats[s] - ref[s])
        rel[s] = d if s == "cage_slip" else d / abs(ref[s])
        in_ci[s] = d / ci[s] if ci[s] > 0 else float("inf")
    return {
        "relative": rel,
        "in_ci_halfwidths": in_ci,
        "max_in_ci": max(in_ci.values()),
        "max_relative_pv_speed": max(rel[s] for s in STATS if s != "cage_slip"),
    }


# -- integrators -----------------------------------------------------------------------------
def compile_solve(bearing, op, num_saves: int, kind: str):
    """Compiled (bearing, op, duration, rtol, atol, loosen, rotation, seed) -> Solution; seed is
    traced, so one program serves every seed, tolerance and loosening (raceway-normal
    `loosen`, `rotation` for the rotations)."""
    import jax.numpy as jnp
    import optimistix as optx

    import jaxbearing as jb

    def run(b, o, d, r, a, loosen, rotation, seed):
        norm = {"rms": optx.rms_norm, "default": "body_rms"}.get(kind, "max")
        return jb.solve(
            b,
            o,
            d,
            solver="ros34pw2" if kind == "ros" else "tsit5",
            num_saves=num_saves,
            rtol=r,
            atol=a,
            raceway_loosen=loosen,
            rotation_loosen=rotation,
            error_norm=norm,
            perturbation=jb.Perturbation(seed=seed),
        )

    f = jnp.asarray
    seed = jnp.asarray(0, jnp.int32)
    return _common.compile_jit(run, bearing, op, f(1e-3), f(1e-3), f(1e-6), f(1.0), f(1.0), seed)


def jacobian_cost(bearing, op, repeats: int = 20) -> dict:
    """Wall time of one field evaluation and of one per-roller block Jacobian (12 JVPs, vmapped;
    `RollerBlockJacobian`) at the initial state, compiled, and their ratio: the Jacobian's cost
    in field evaluations."""
    import jax
    import jax.numpy as jnp

    import jaxbearing as jb
    from jaxbearing.run import scaled_field
    from jaxbearing.run._rosenbrock import RollerBlockJacobian

    field = _common.FlatField(bearing, op, perturbation=jb.Perturbation(seed=0))
    y0 = field._unravel_state(field.y0)
    t0 = jnp.asarray(1e-4)
    f = jax.jit(lambda t, y, a: scaled_field(t, y, a))
    jac = jax.jit(lambda t, y, a: RollerBlockJacobian()(lambda t_, y_: scaled_field(t_, y_, a), t, y).blocks)
    out = {}
    for name, fn in (("field_s", f), ("jacobian_s", jac)):
        times = _common.time_repeats(lambda fn=fn: fn(t0, y0, field.args), repeats)
        out[name] = min(times)
    out["jacobian_cost_in_evaluations"] = out["jacobian_s"] / out["field_s"]
    return out


def run_solve(
    compiled, bearing, op, duration, rtol, atol, loosen, seed, kind="solve", jac_cost=0.0, rotation=1.0
) -> dict:
    import jax.numpy as jnp

    f = jnp.asarray
    wall, sol = _common.time_once(
        lambda: compiled(
            bearing, op, f(duration), f(rtol), f(atol), f(loosen), f(rotation), jnp.asarray(seed, jnp.int32)
        )
    )
    out = solve_record(wall, sol.result, sol.num_steps, sol.num_rejected_steps, sol.histories)
    out["mean_accepted_step_us"] = (
        1e6 * float(duration) / max(out["step_attempts"] - out["rejected_steps"], 1)
    )
    if kind == "ros":
        # ROS34PW2, FSAL: 3 new stages + f(t1, y1) per attempt, f(t0, y0) once; one block
        # Jacobian per attempt (refresh every step) and one at the start
        out["field_evaluations"] = 4 * out["step_attempts"] + 1
        out["jacobians"] = out["step_attempts"] + 1
        out["evaluations"] = out["field_evaluations"] + jac_cost * out["jacobians"]
    return out


def solve_record(wall, code, steps, rejected, hist) -> dict:
    """A Tsit5 run's record (`bench_work_precision_settled` too): success, wall time, step
    attempts, rejected steps, field evaluations (`_common.fsal_rk_evaluations`), the samples."""
    import jax
    import numpy as np

    return {
        "ok": int(code) == 0,
        "wall_s": wall,
        "step_attempts": int(steps),
        "rejected_steps": int(rejected),
        "evaluations": _common.fsal_rk_evaluations(steps),
        "hist": jax.tree_util.tree_map(np.asarray, hist),
    }


class ScipyRunner:
    """SciPy RK45 on the compiled flat field; histories from the same contact functions."""

    def __init__(self, bearing, op):
        import jax

        import jaxbearing as jb

        self.bearing, self.op = bearing, op
        self.field0 = _common.FlatField(bearing, op, perturbation=jb.Perturbation(seed=0))
        self.compiled_field, self.compile_s = self.field0.compile()
        field0 = self.field0

        def samples(ts, ys, args_flat):
            from jaxbearing.dynamics import contact_loads

            args = field0._unravel_args(args_flat)

            def one(t, y):
                state = args.scaling.unscale(t, field0._unravel_state(y))
                fl = contact_loads(state, args.params).flange
                return {
                    "t": t,
                    "flange_force": fl.normal_force,
                    "flange_pv": fl.pv,
                    "flange_sliding_speed": fl.sliding_speed,
                    "cage_speed": state.cage.speed,
                }

            return jax.vmap(one)(ts, ys)

        self.samples = jax.jit(samples)
        self._warm: set[int] = set()

    def warm_samples(self, num_saves: int, args_flat) -> None:
        """Compile `samples` for `num_saves` samples before a timed run (once per count)."""
        import numpy as np

        if num_saves not in self._warm:
            ts = np.zeros(num_saves)
            self.samples(ts, np.zeros((num_saves, self.field0.size)), args_flat)
            self._warm.add(num_saves)

    def run(self, duration, num_saves, rtol, atol, seed) -> dict:
        """From seed `seed`'s quasi-static start (`run_from`)."""
        import jaxbearing as jb

        field = _common.FlatField(self.bearing, self.op, perturbation=jb.Perturbation(seed=seed))
        return self.run_from(field.y0, field.args_flat, duration, num_saves, rtol, atol)

    def run_from(self, y0, args_flat, duration, num_saves, rtol, atol) -> dict:
        """RK45 from the flat scaled state `y0` with the flat arguments `args_flat`, sampled at
        `num_saves` equally spaced instants of [0, duration]."""
        import jax
        import numpy as np
        from scipy.integrate import solve_ivp

        self.warm_samples(num_saves, args_flat)
        start = time.perf_counter()
        sol = solve_ivp(
            lambda t, y: np.asarray(self.compiled_field(t, y, args_flat)),
            (0.0, duration),
            np.asarray(y0),
            method="RK45",
            rtol=rtol,
            atol=atol,
            t_eval=np.linspace(0.0, duration, num_saves),
        )
        # the samples are part of the run, as in `jaxbearing.solve` (histories after the loop)
        hist = jax.tree_util.tree_map(np.asarray, self.samples(sol.t, sol.y.T, args_flat))
        return {
            "ok": sol.status == 0,
            "wall_s": time.perf_counter() - start,
            "step_attempts": _common.rk45_attempts(sol.nfev),
            "rejected_steps": None,  # t_eval given: sol.t does not list the accepted steps
            "evaluations": int(sol.nfev),
            "hist": hist,
        }


# -- the benchmark -----------------------------------------------------------------------------
def main(quick: bool = False, imex: bool = False, rows: tuple | None = None, corner: bool = False) -> dict:

    import jaxbearing as jb

    started = time.perf_counter()
    t0, window = (1e-3, 1e-3) if quick else (2e-3, 6e-3)
    seeds = (0,) if quick else (0, 1)
    duration = t0 + window
    num_saves = int(round(duration / SAMPLE_DT)) + 1
    bearing, op = jb.reference_bearing(), jb.reference_operating_point()
    if corner:
        bearing = bearing.with_flat_ends()
    jb.validate_bearing(bearing, op)
    omega_kin = float(jb.kinematic_cage_speed(bearing, op))
    variants = [VARIANTS[i] for i in QUICK_VARIANTS] if quick else list(VARIANTS)
    if imex:
        variants = [VARIANTS[i] for i in IMEX_VARIANTS]
    if rows is not None:
        variants = [VARIANTS[i] for i in rows]

    _common.log(
        f"{NAME}: compiling solve (max/weighted norm), {num_saves} samples over {duration * 1e3:g} ms"
    )
    programs = {"solve": compile_solve(bearing, op, num_saves, "solve")}
    for kind in ("rms", "default"):
        if any(v[1] == kind for v in variants):
            programs[kind] = compile_solve(bearing, op, num_saves, kind)
    jac = None
    if any(v[1] == "ros" for v in variants):
        _common.log(f"{NAME}: compiling the Rosenbrock-W solve")
        programs["ros"] = compile_solve(bearing, op, num_saves, "ros")
        jac = jacobian_cost(bearing, op)
        _common.log(f"{NAME}: block Jacobian = {jac['jacobian_cost_in_evaluations']:.2f} field evaluations")
    scipy_runner = ScipyRunner(bearing, op) if any(v[1] == "scipy" for v in variants) else None
    compile_s = {k: v[1] for k, v in programs.items()}
    if scipy_runner is not None:
        compile_s["scipy_field"] = scipy_runner.compile_s

    def run(kind, rtol, atol, loosen, seed, rotation=1.0):
        if kind == "scipy":
            return scipy_runner.run(duration, num_saves, rtol, atol, seed)
        cost = jac["jacobian_cost_in_evaluations"] if kind == "ros" else 0.0
        return run_solve(
            programs[kind][0], bearing, op, duration, rtol, atol, loosen, seed, kind, cost, rotation
        )

    reference = {}
    for seed in seeds:
        _common.log(f"{NAME}: reference (rtol {REF_RTOL:g}), seed {seed}")
        r = run("solve", REF_RTOL, REF_ATOL, 1.0, seed)
        if not r["ok"]:
            raise RuntimeError(f"the reference solve failed (seed {seed})")
        hist = r.pop("hist")
        r["statistics"] = window_statistics(hist, t0, omega_kin)
        r["ci_halfwidth"] = confidence_halfwidths(hist, t0, omega_kin)
        r["evaluations_per_ms"] = r["evaluations"] / (duration * 1e3)
        reference[str(seed)] = r

    rows = []
    for label, kind, rtol, atol, loosen, *rest in variants:
        rotation = rest[0] if rest else 1.0
        per_seed = {}
        for seed in seeds:
            _common.log(f"{NAME}: {label}, seed {seed}")
            r = run(kind, rtol, atol, loosen, seed, rotation)
            hist = r.pop("hist")
            ref = reference[str(seed)]
            r["statistics"] = window_statistics(hist, t0, omega_kin)
            r["errors"] = errors(r["statistics"], ref["statistics"], ref["ci_halfwidth"])
            r["evaluations_per_ms"] = r["evaluations"] / (duration * 1e3)
            r["wall_s_per_ms"] = r["wall_s"] / (duration * 1e3)
            per_seed[str(seed)] = r
        rows.append(
            {
                **variant_row(label, kind, rtol, atol, loosen, per_seed),
                "rotation_loosen": rotation,
                "max_relative_error_pv_speed": max(
                    s["errors"]["max_relative_pv_speed"] for s in per_seed.values()
                ),
                "max_cage_slip_error": max(s["errors"]["relative"]["cage_slip"] for s in per_seed.values()),
            }
        )
    base = rows[0]
    for row in rows:
        row["evaluation_ratio_vs_old_default"] = base["evaluations_per_ms"] / row["evaluations_per_ms"]
        row["wall_ratio_vs_old_default"] = base["wall_s_per_ms"] / row["wall_s_per_ms"]
    result = {
        "benchmark": NAME,
        "quick": quick,
        "case": {
            "bearing": f"reference_bearing() (26 rollers, 31 slices, {'corner' if corner else 'arc'} ends)",
            "inner_speed_rpm": float(jb.rad_s_to_rpm(op.inner_speed)),
            "radial_load_N": float(op.radial_load),
            "startup_s": t0,
            "window_s": window,
            "seeds": list(seeds),
            "sample_dt_s": SAMPLE_DT,
            "reference": {"rtol": REF_RTOL, "atol": REF_ATOL, "method": "Tsit5, max norm"},
            "note": "fixed start-up time then a fixed window (no settling detection); CI from 8 batch "
            "means of the reference over the window; errors of cage slip are absolute",
        },
        "compile_s": compile_s,
        "jacobian_cost": jac,
        "reference": reference,
        "variants": rows,
        "benchmark_wall_s": time.perf_counter() - started,
    }
    result["table"] = _table(result)
    print(result["table"])
    suffix = ("_imex" if imex else "") + ("_rows" if rows is not None else "") + ("_corner" if corner else "")
    _common.write_json(NAME + suffix, result)
    return result


def rows_argument(argv: list, count: int) -> tuple | None:
    """The indices given by `--rows i,j,...` in `argv` (None without `--rows`), each in [0,
    `count`); anything else ends the program with one line naming the option, its value and
    the valid range."""
    text = _common.option_value(argv, "--rows")
    if text is None:
        return None
    parts = text.split(",")
    if not all(i.strip().isdigit() for i in parts) or any(not 0 <= int(i) < count for i in parts):
        raise SystemExit(
            f"--rows = {text!r}: comma-separated indices of VARIANTS in [0, {count - 1}], e.g. 0,3"
        )
    return tuple(int(i) for i in parts)


def variant_row(label: str, kind: str, rtol: float, atol: float, loosen: float, per_seed: dict) -> dict:
    """One integrator's summary over its seeds (`per_seed`: {seed: run with "ok",
    "evaluations_per_ms", "wall_s_per_ms" and "errors"}); `bench_work_precision_settled` too."""
    import numpy as np

    runs = list(per_seed.values())
    return {
        "label": label,
        "kind": kind,
        "rtol": rtol,
        "atol": atol,
        "raceway_loosen": loosen,
        "seeds": per_seed,
        "all_ok": all(s["ok"] for s in runs),
        "evaluations_per_ms": float(np.mean([s["evaluations_per_ms"] for s in runs])),
        "wall_s_per_ms": float(np.mean([s["wall_s_per_ms"] for s in runs])),
        "max_error_in_ci": max(s["errors"]["max_in_ci"] for s in runs),
    }


def _table(r: dict) -> str:
    c = r["case"]
    rows = []
    for ref_seed, ref in r["reference"].items():
        st = ref["statistics"]
        rows.append(
            [
                f"reference rtol {c['reference']['rtol']:g} (seed {ref_seed})",
                ref["evaluations_per_ms"],
                None,
                ref["wall_s"] / ((c["startup_s"] + c["window_s"]) * 1e3),
                None,
                st["mean_pv"] / 1e6,
                st["p95_pv"] / 1e6,
                st["mean_sliding_speed"],
                100 * st["cage_slip"],
                None,
                None,
                None,
            ]
        )
    for v in r["variants"]:
        s0 = next(iter(v["seeds"].values()))["statistics"]
        rows.append(
            [
                v["label"],
                v["evaluations_per_ms"],
                v["evaluation_ratio_vs_old_default"],
                v["wall_s_per_ms"],
                v["wall_ratio_vs_old_default"],
                s0["mean_pv"] / 1e6,
                s0["p95_pv"] / 1e6,
                s0["mean_sliding_speed"],
                100 * s0["cage_slip"],
                v["max_relative_error_pv_speed"],
                100 * v["max_cage_slip_error"],
                v["max_error_in_ci"],
            ]
        )
    return _common.format_table(
        f"Work-precision: reference bearing {c['inner_speed_rpm']:.0f} rpm, {c['radial_load_N']:.0f} N; statistics over "
        f"[{c['startup_s'] * 1e3:g}, {(c['startup_s'] + c['window_s']) * 1e3:g}] ms, seeds {c['seeds']} "
        f"(statistics columns: first seed; errors: worst seed)",
        [
            "integrator",
            "evals/ms",
            "x fewer",
            "wall s/ms",
            "x faster",
            "mean PV MPa m/s",
            "p95 PV",
            "mean u m/s",
            "slip %",
            "max rel err PV,u",
            "slip err %pt",
            "err / CI",
        ],
        rows,
    )


def self_check() -> None:
    """Cheap checks of the statistics (no model compile)."""
    import numpy as np

    t = np.linspace(0.0, 1.0, 81)
    q = np.zeros((81, 2, 4))
    q[:, 0, 0] = 10.0
    hist = {
        "t": t,
        "flange_force": q,
        "flange_pv": q * 2.0,
        "flange_sliding_speed": q * 0.1,
        "cage_speed": np.full(81, 99.0),
    }
    s = window_statistics(hist, 0.5, 100.0)
    assert abs(s["mean_pv"] - 20.0) < 1e-12 and abs(s["p95_pv"] - 20.0) < 1e-12
    assert abs(s["cage_slip"] - 0.01) < 1e-12 and s["contact_samples"] == 41
    ci = confidence_halfwidths(hist, 0.5, 100.0)
    assert all(v == 0.0 for v in ci.values())


if __name__ == "__main__":
    selected = rows_argument(sys.argv, len(VARIANTS))  # --rows 0,3,13 -> bench_work_precision_rows.json
    main(quick="--quick" in sys.argv, imex="--imex" in sys.argv, rows=selected, corner="--corner" in sys.argv)
