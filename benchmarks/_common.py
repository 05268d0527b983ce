"""Shared helpers of the benchmarks: timing, machine information, JSON results, tables, and the
flat (raveled) form of the model's vector field that an external integrator can drive.

Every number a benchmark reports is measured here at run time; nothing is typed in.

Timing conventions
------------------
* Compile time is measured separately (`jax.jit(...).lower(...).compile()`), and run times
  always exclude it: the compiled executable is called, and `jax.block_until_ready` waits for
  the result before the clock stops.
* Repeated timings are summarised by the median (robust against the odd slow call) and the
  minimum (the least-disturbed call, the usual `timeit` convention on a shared machine).
* The machine information (CPU count, load average, versions) goes into every JSON file, so a
  number can be read against the conditions it was taken in. On a shared 2-core machine the
  load average matters: ratios measured back to back (SciPy vs diffrax) are more robust than
  absolute times.
"""

from __future__ import annotations

import datetime as _dt
import json
import math
import os
import platform
import statistics
import sys
import time
from collections.abc import Callable, Sequence
from pathlib import Path
from typing import Any

BENCH_DIR = Path(__file__).resolve().parent
RESULTS_DIR = BENCH_DIR / "results"


# -- machine ---------------------------------------------------------------------------------
def machine_info() -> dict:
    """CPU count, load, platform, Python/JAX/diffrax/SciPy versions, JAX backend, date (UTC)."""
    import jax
    import numpy as np
    import scipy

    try:
        import diffrax

        diffrax_version = diffrax.__version__
    except Exception:  # pragma: no cover - diffrax is a dependency
        diffrax_version = None
    try:
        affinity = len(os.sched_getaffinity(0))
    except AttributeError:  # pragma: no cover - not on Linux
        affinity = os.cpu_count()
    try:
        load = [round(x, 2) for x in os.getloadavg()]
    except OSError:  # pragma: no cover
        load = None
    return {
        "date_utc": _dt.datetime.now(_dt.UTC).isoformat(timespec="seconds"),
        "cpu_count": os.cpu_count(),
        "cpu_affinity": affinity,
        "cpu_model": _cpu_model(),
        "load_average_1_5_15min": load,
        "platform": platform.platform(),
        "python": platform.python_version(),
        "jax": jax.__version__,
        "jax_backend": jax.default_backend(),
        "jax_devices": [str(d) for d in jax.devices()],
        "jax_enable_x64": bool(jax.config.jax_enable_x64),
        "diffrax": diffrax_version,
        "scipy": scipy.__version__,
        "numpy": np.__version__,
    }


def _cpu_model() -> str | None:
    try:
        with open("/proc/cpuinfo") as fh:
            for line in fh:
                if line.startswith("model name"):
                    return line.split(":", 1)[1].strip()
    except OSError:
        pass
    return platform.processor() or None


# -- timing ----------------------------------------------------------------------------------
_T0 = time.perf_counter()


def option_value(argv: Sequence[str], option: str) -> str | None:
    """The word after `option` in `argv` ("" when `option` is last), None without `option`: the
    command-line options of the benchmarks, each then checked by its script."""
    if option not in argv:
        return None
    at = list(argv).index(option) + 1
    return argv[at] if at < len(argv) else ""


def log(message: str) -> None:
    """A progress line on stderr, stamped with seconds since import (the tables go to stdout)."""
    print(f"[{time.perf_counter() - _T0:7.1f} s] {message}", file=sys.stderr, flush=True)


def block(x):
    """Wait for every array in a pytree (JAX dispatch is asynchronous)."""
    import jax

    return jax.block_until_ready(x)


def time_once(fn: Callable[[], Any]) -> tuple[float, Any]:
    """(seconds, result) of one call, waiting for the result."""
    start = time.perf_counter()
    out = block(fn())
    return time.perf_counter() - start, out


def time_repeats(fn: Callable[[], Any], repeats: int, warmup: int = 1) -> list[float]:
    """Seconds of `repeats` calls (after `warmup` untimed calls), each waited for."""
    for _ in range(warmup):
        block(fn())
    return [time_once(fn)[0] for _ in range(repeats)]


def summary_stats(times: Sequence[float]) -> dict:
    """median, min, max and count of a list of timings [s]."""
    return {
        "median_s": statistics.median(times),
        "min_s": min(times),
        "max_s": max(times),
        "repeats": len(times),
    }


def compile_jit(fn: Callable, *args) -> tuple[Any, float]:
    """Ahead-of-time compile `jax.jit(fn)` for `args`: (compiled executable, seconds)."""
    import jax

    start = time.perf_counter()
    compiled = jax.jit(fn).lower(*args).compile()
    return compiled, time.perf_counter() - start


# -- results ---------------------------------------------------------------------------------
def _jsonable(x):
    import numpy as np

    if isinstance(x, dict):
        return {str(k): _jsonable(v) for k, v in x.items()}
    if isinstance(x, list | tuple):
        return [_jsonable(v) for v in x]
    if isinstance(x, np.ndarray) or hasattr(x, "__array__") and not isinstance(x, str | bytes):
        arr = np.asarray(x)
        return _jsonable(arr.item() if arr.ndim == 0 else arr.tolist())
    if isinstance(x, np.generic):
        return _jsonable(x.item())
    if isinstance(x, float) and not math.isfinite(x):
        return None if math.isnan(x) else ("inf" if x > 0 else "-inf")
    return x


def write_json(name: str, data: dict, results_dir: Path | str | None = None) -> Path:
    """Write `data` (with a `machine` block added if missing) to `<results>/<name>.json`.

    Written through a temporary file and renamed, so a crashed run never leaves half a file.
    NaN becomes null and infinities the strings "inf"/"-inf" (strict JSON)."""
    out_dir = Path(results_dir) if results_dir is not None else RESULTS_DIR
    out_dir.mkdir(parents=True, exist_ok=True)
    payload = dict(data)
    payload.setdefault("benchmark", name)
    payload.setdefault("machine", machine_info())
    path = out_dir / f"{name}.json"
    tmp = path.with_suffix(".json.tmp")
    tmp.write_text(json.dumps(_jsonable(payload), indent=2, allow_nan=False) + "\n")
    tmp.replace(path)
    return path


def format_table(title: str, header: Sequence[str], rows: Sequence[Sequence[Any]]) -> str:
    """A plain-text table: numbers to 4 significant figures, columns right-aligned."""

    def cell(v) -> str:
        if isinstance(v, bool) or v is None:
            return {True: "yes", False: "no", None: "-"}[v]
        if isinstance(v, int):
            return str(v)
        if isinstance(v, float):
            if not math.isfinite(v):
                return str(v)
            if v != 0 and (abs(v) >= 1e5 or abs(v) < 1e-3):
                return f"{v:.3e}"
            return f"{v:.4g}"
        return str(v)

    cells = [[cell(v) for v in row] for row in rows]
    widths = [max(len(str(h)), *(len(r[i]) for r in cells)) for i, h in enumerate(header)]
    line = "  ".join("-" * w for w in widths)
    out = [title, line, "  ".join(str(h).rjust(w) for h, w in zip(header, widths)), line]
    out += ["  ".join(c.rjust(w) for c, w in zip(r, widths)) for r in cells]
    out.append(line)
    return "\n".join(out)


def target(description: str, measured: float, threshold: float, higher_is_better: bool) -> dict:
    """A performance target of issue 8, evaluated on a measured value."""
    ok = measured >= threshold if higher_is_better else measured <= threshold
    return {
        "target": description,
        "measured": measured,
        "threshold": threshold,
        "reached": bool(ok) if math.isfinite(measured) else False,
    }


# -- settled runs: per-seed means and differences ----------------------------------------------
def seed_revolution_values(result, threshold: float = 1.0) -> list[dict]:
    """Per seed of a settled run (`jaxbearing.simulate_steady`), one value per window revolution
    of every settled statistic (`jaxbearing.run.revolution_statistics`), plus
    `total_flange_load_N` (time-mean of the sum of all flange normal forces) and, where the
    histories hold the friction coefficient, `total_flange_friction_N` (time-mean of the sum of
    mu Q over all flange contacts), `flange_friction_contact_time_N.mean` (mean of mu Q over the
    contact time, samples with Q > `threshold`) and `flange_friction_coefficient.mean` (mean mu
    over the contact time). The friction force is taken as mu Q: the model's
    mu Q |u| / sqrt(|u|^2 + u_eps^2) with u_eps = 1 mm/s differs from it by less than 1e-8
    relative at the sliding speeds of the reference point (several m/s)."""
    import numpy as np

    from jaxbearing.geometry import kinematic_cage_speed, limited_circle_radius
    from jaxbearing.run import revolution_statistics

    rho_lim = float(limited_circle_radius(result.bearing.roller))
    kin = float(kinematic_cage_speed(result.bearing, result.operating))
    out = []
    for run in result.runs:
        w, edges = run.window, np.asarray(run.edges)
        vals = revolution_statistics(w, edges, rho_lim, kin, threshold)
        t = np.asarray(w["t"])
        q = np.asarray(w["flange_force"])
        mu = np.asarray(w["flange_friction_coefficient"]) if "flange_friction_coefficient" in w else None
        extra = {
            "total_flange_load_N": [],
            "total_flange_friction_N": [],
            "flange_friction_contact_time_N.mean": [],
        }
        extra["flange_friction_coefficient.mean"] = []
        for a, b in zip(edges[:-1], edges[1:]):
            sel = (t >= a) & (t < b)
            extra["total_flange_load_N"].append(float(np.mean(q[sel].sum(axis=(1, 2)))))
            if mu is not None:
                f = mu[sel] * q[sel]
                touching = q[sel] > threshold
                extra["total_flange_friction_N"].append(float(np.mean(f.sum(axis=(1, 2)))))
                extra["flange_friction_contact_time_N.mean"].append(
                    float(np.mean(f[touching])) if touching.any() else float("nan")
                )
                extra["flange_friction_coefficient.mean"].append(
                    float(np.mean(mu[sel][touching])) if touching.any() else float("nan")
                )
        vals.update({k: np.asarray(v) for k, v in extra.items() if v})
        out.append(vals)
    return out


def seed_means(result, threshold: float = 1.0) -> dict[str, list[float]]:
    """{statistic: [each seed's window mean]} (NaN revolutions left out, as the settled
    statistics do)."""
    import numpy as np

    per_seed = seed_revolution_values(result, threshold)
    return {
        k: [float(np.nanmean(v[k])) if np.isfinite(v[k]).any() else float("nan") for v in per_seed]
        for k in per_seed[0]
    }


def interval(samples) -> dict:
    """Mean and 95 % Student-t interval (N-1 dof) of `samples` (`jaxbearing.run.student_t_interval`)."""
    from jaxbearing.run import student_t_interval

    return student_t_interval(list(samples)).as_dict()


def welch_difference(a, b) -> dict:
    """mean(b) - mean(a) of two independent samples and its Welch 95 % interval
    (Welch-Satterthwaite degrees of freedom); `resolved` when the interval excludes 0."""
    import numpy as np
    from scipy import stats

    xa, xb = np.asarray(a, float), np.asarray(b, float)
    diff = float(xb.mean() - xa.mean())
    va, vb = xa.var(ddof=1) / xa.size, xb.var(ddof=1) / xb.size
    se = math.sqrt(va + vb)
    if se == 0.0:
        return {"value": diff, "ci95_low": diff, "ci95_high": diff, "dof": None, "resolved": diff != 0.0}
    dof = (va + vb) ** 2 / (va**2 / (xa.size - 1) + vb**2 / (xb.size - 1))
    h = float(stats.t.ppf(0.975, dof)) * se
    lo, hi = diff - h, diff + h
    return {
        "value": diff,
        "ci95_low": lo,
        "ci95_high": hi,
        "dof": float(dof),
        "resolved": bool(lo > 0 or hi < 0),
    }


# -- the model's vector field in flat form -----------------------------------------------------
class FlatField:
    """The vector field diffrax integrates in `jaxbearing.solve`, as flat float64 vectors.

    `jaxbearing.run.solve` integrates the *scaled deviation* state
    Y = (y - nominal(t)) / scale (`jaxbearing.dynamics.Scaling`) with the field
    `jaxbearing.run.scaled_field(t, Y, args)`. This object builds exactly the same `args` and
    initial Y as `solve` does, ravels Y with `jax.flatten_util.ravel_pytree`, and ravels the
    arguments too, so that one compiled call takes three arrays (t, Y_flat, args_flat):
    the cheapest dispatch for an external integrator (`scipy.integrate.solve_ivp`).
    """

    def __init__(self, bearing, op, perturbation="default", functionals=None):
        import jax.numpy as jnp
        from jax.flatten_util import ravel_pytree

        from jaxbearing.dynamics import Functionals, Params, Scaling, state_scales
        from jaxbearing.geometry import kinematic_cage_speed
        from jaxbearing.run import Perturbation, SolveArgs, initial_state

        if perturbation == "default":
            perturbation = Perturbation()  # the default of `solve`
        functionals = Functionals() if functionals is None else functionals
        y0 = initial_state(bearing, op, perturbation)
        scaling = Scaling(
            nominal=y0,
            scale=state_scales(bearing.num_rollers, bearing.pitch_diameter / 2),
            orbit_speed=kinematic_cage_speed(bearing, op),
        )
        self.args = SolveArgs(
            params=Params(bearing=bearing, operating=op, functionals=functionals), scaling=scaling
        )
        self.functionals = functionals
        y0_scaled = scaling.scale_state(0.0, y0)
        self.y0, self._unravel_state = ravel_pytree(y0_scaled)
        self.args_flat, self._unravel_args = ravel_pytree(self.args)
        self.t0 = jnp.asarray(0.0)
        self.size = int(self.y0.size)

    def __call__(self, t, y_flat, args_flat):
        """Flat scaled rate dY/dt (pure; jit this)."""
        from jax.flatten_util import ravel_pytree

        from jaxbearing.run import scaled_field

        rate = scaled_field(t, self._unravel_state(y_flat), self._unravel_args(args_flat))
        return ravel_pytree(rate)[0]

    def compile(self):
        """(compiled field(t, Y_flat, args_flat), compile seconds)."""
        return compile_jit(self.__call__, self.t0, self.y0, self.args_flat)

    def physical(self, t, y_flat):
        """The physical state (unscaled `jaxbearing.dynamics.State`) of a flat scaled state."""
        import jax.numpy as jnp

        return self.args.scaling.unscale(jnp.asarray(t, float), self._unravel_state(jnp.asarray(y_flat)))


def count_calls(fun: Callable) -> Callable:
    """Wrap `fun` so that `wrapper.calls` counts its calls."""

    def wrapper(*args, **kwargs):
        wrapper.calls += 1
        return fun(*args, **kwargs)

    wrapper.calls = 0
    return wrapper


def fsal_rk_evaluations(num_steps: int) -> int:
    """Vector-field evaluations of a diffrax solve with Tsit5 or Dopri5.

    Both have 7 stages and are first-same-as-last (FSAL): the first stage of a step is the last
    stage of the previous accepted step, so every step attempt (accepted or rejected) costs
    6 new evaluations, and the very first step one more for f(t0, y0); a rejected step keeps
    the FSAL value (its y0 did not change). diffrax's `num_steps` statistic (and so
    `jaxbearing.Solution.num_steps`) counts step *attempts*: accepted = num_steps -
    num_rejected_steps. Hence

        evaluations = 6 num_steps + 1.

    (The dense output behind `SaveAt(ts=...)` reuses the stored stages: no extra evaluations.)
    `bench_scipy` verifies this by counting the calls of an instrumented field.
    """
    return 6 * int(num_steps) + 1


def rk45_attempts(nfev: int) -> int:
    """Step attempts of SciPy's RK45 from its evaluation count.

    `scipy.integrate.RK45` evaluates f(t0, y0) once and once more to choose the initial step
    (`select_initial_step`), then 6 evaluations per attempt (Dormand-Prince, FSAL):
    nfev = 2 + 6 attempts."""
    return (int(nfev) - 2) // 6


def run_solve_ivp(fun: Callable, t_span, y0, *, rtol: float, atol: float, method: str = "RK45"):
    """`scipy.integrate.solve_ivp` with evaluation counting and timing.

    Returns a dict: wall_s, nfev (SciPy's), calls (counted), accepted steps (len(sol.t) - 1;
    no t_eval, so sol.t holds every accepted step), attempts, rejected, status, message, y1."""
    import numpy as np
    from scipy.integrate import solve_ivp

    counted = count_calls(fun)
    start = time.perf_counter()
    sol = solve_ivp(counted, t_span, np.asarray(y0, dtype=float), method=method, rtol=rtol, atol=atol)
    wall = time.perf_counter() - start
    accepted = len(sol.t) - 1
    attempts = rk45_attempts(sol.nfev) if method == "RK45" else None
    return {
        "wall_s": wall,
        "nfev": int(sol.nfev),
        "calls": counted.calls,
        "accepted_steps": accepted,
        "attempts": attempts,
        "rejected_steps": None if attempts is None else attempts - accepted,
        "status": int(sol.status),
        "message": str(sol.message),
        "t1": float(sol.t[-1]),
        "y1": sol.y[:, -1],
    }
