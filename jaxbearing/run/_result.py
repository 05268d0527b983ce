"""What a run returns: the raw `Solution` of `solve` (JAX arrays, vmappable), its outcome code
(`result_code`, `RESULT_NAMES`), the smooth peak functionals of the integrated accumulators, and
the `SimulationResult` of `simulate` (numpy histories, status text naming a failure and the
simulated time it reached)."""

from __future__ import annotations

import dataclasses

import diffrax
import equinox as eqx
import jax
import jax.numpy as jnp
import numpy as np
from jaxtyping import Array

from ..dynamics import (
    Accumulators,
    Functionals,
)
from ..geometry import Bearing, OperatingPoint


def smooth_functionals(acc: Accumulators, functionals: Functionals):
    """(smooth peak PV, smooth max and min contact height) from the integrated accumulators.

    peak PV  = PV_ref (sum int w PV^p dt / sum int w dt)^(1/p)        (p-norm over contact time)
    max h_c  = h_ref + log(sum int w e^{beta dh} dt / sum int w dt) / beta   (log-sum-exp)
    min h_c  = h_ref - log(sum int w e^{-beta dh} dt / sum int w dt) / beta
    Sums run over every roller and flange. Both tend to the true extremes as p, beta grow.

    Without any flange contact (all accumulators zero) the peak PV is 0 and the heights are NaN
    (there is no contact height); the double-`where` keeps every gradient finite there.
    """
    ct = jnp.sum(acc.contact_time)
    pv_sum = jnp.sum(acc.pv_power)
    hi_sum, lo_sum = jnp.sum(acc.height_max_power), jnp.sum(acc.height_min_power)
    has_pv = (pv_sum > 0) & (ct > 0)
    has_h = (hi_sum > 0) & (lo_sum > 0) & (ct > 0)
    safe_ct = jnp.where(ct > 0, ct, 1.0)
    pv_ratio = jnp.where(has_pv, pv_sum / safe_ct, 1.0)
    pv = jnp.where(has_pv, functionals.pv_reference * pv_ratio ** (1.0 / functionals.pv_exponent), 0.0)
    hi = jnp.log(jnp.where(has_h, hi_sum / safe_ct, 1.0)) / functionals.height_sharpness
    lo = jnp.log(jnp.where(has_h, lo_sum / safe_ct, 1.0)) / functionals.height_sharpness
    h_max = jnp.where(has_h, functionals.height_reference + hi, jnp.nan)
    h_min = jnp.where(has_h, functionals.height_reference - lo, jnp.nan)
    return pv, h_max, h_min


@dataclasses.dataclass
class SimulationResult:
    """Histories (numpy, leading axis time), smooth peak functionals and solver status."""

    status: str
    ok: bool
    reached_time: float
    num_steps: int
    num_rejected_steps: int
    wall_time_s: float
    compile_time_s: float
    histories: dict
    smooth_peak_pv: float
    smooth_max_contact_height: float
    smooth_min_contact_height: float
    bearing: Bearing
    operating: OperatingPoint


class Solution(eqx.Module):
    """Raw output of `solve` (JAX arrays; vmappable). `histories` has a leading time axis."""

    histories: dict
    accumulators: Accumulators
    result: Array  # outcome code: index into RESULT_NAMES (0 = successful)
    num_steps: Array
    num_rejected_steps: Array


#: outcomes of a solve, by their `diffrax.RESULTS` names; `Solution.result` is the index here
#: (0 = successful; len(RESULT_NAMES) = an outcome not listed). A stable code, independent of
#: diffrax's internal numbering.
RESULT_NAMES = (
    "successful",
    "max_steps_reached",
    "dt_min_reached",
    "nonfinite",
    "max_steps_rejected",
    "event_occurred",
    "internal_error",
)
_RESULT_TEXT = {
    "max_steps_reached": "the step limit max_steps was reached",
    "dt_min_reached": "the step size collapsed below dtmin (non-finite or unresolvable dynamics)",
}


def result_code(result) -> Array:
    """The index in `RESULT_NAMES` of a `diffrax.RESULTS` value (public API: comparisons with
    the RESULTS members), int32; works under jit and vmap."""
    code = jnp.asarray(len(RESULT_NAMES), dtype=jnp.int32)
    for i, name in reversed(tuple(enumerate(RESULT_NAMES))):
        member = getattr(diffrax.RESULTS, name, None)
        if member is not None:
            code = jnp.where(result == member, jnp.int32(i), code)
    return code


def result_message(code: int) -> str:
    name = RESULT_NAMES[code] if 0 <= code < len(RESULT_NAMES) else "other"
    return _RESULT_TEXT.get(name, f"the solver did not succeed ({name}, result code {code})")


def simulation_result(
    sol: Solution, bearing, op, functionals, duration, wall, compile_time
) -> SimulationResult:
    hist = jax.tree_util.tree_map(np.asarray, sol.histories)
    code = int(sol.result)
    ok = code == 0
    t_saved = hist["t"]
    finite = np.isfinite(t_saved) & np.all(np.isfinite(hist["cage_speed"].reshape(len(t_saved), -1)), axis=1)
    # diffrax fills samples after a failure with inf; keep the samples actually reached
    hist = {k: v[finite] for k, v in hist.items()}
    reached = float(hist["t"][-1]) if finite.any() else 0.0
    if ok:
        status = "ok"
        pv_peak, h_max, h_min = (float(v) for v in smooth_functionals(sol.accumulators, functionals))
    else:
        status = (
            f"failed: {result_message(code)} (simulated time reached {reached * 1e3:.4f} ms"
            f" of {duration * 1e3:.4f} ms)"
        )
        pv_peak = h_max = h_min = float("nan")
    return SimulationResult(
        status=status,
        ok=ok,
        reached_time=reached,
        num_steps=int(sol.num_steps),
        num_rejected_steps=int(sol.num_rejected_steps),
        wall_time_s=wall,
        compile_time_s=compile_time,
        histories=hist,
        smooth_peak_pv=pv_peak,
        smooth_max_contact_height=h_max,
        smooth_min_contact_height=h_min,
        bearing=bearing,
        operating=op,
    )
