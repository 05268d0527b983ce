"""The frozen-load estimator of the gradient of the steady-running design objective
(docs/model.md 17; the objective, its statistics and the ratio estimator: `_steady_objective`).

Estimator. From each of K settled states of design d, a plain solve over a short window saves
the state at equally spaced times. At every saved state the flange PV of each roller-end/flange
contact is differentiated in the design at the loads Q0 the dynamics gave there (the load held
frozen): by Hertz, p_max = c(radii) Q^(1/3), so PV_c(d) (Q0_c / Q_c(d))^(1/3) is the PV at load Q0
with the contact point, curvatures and sliding velocity of design d. The per-trajectory sums
A_k, C_k of the smooth-indicator-weighted samples and their Jacobians are combined through the
ratio estimator, with the jackknife over the trajectories. The tail statistic applies the same
estimator to the Rockafellar-Uryasev integrand at the 95th percentile of the trajectories' own
touching samples (`tail_integrals`; `_steady_objective`, the tail statistic). The friction
statistic holds the loads the same way: per saved state sum_c mu_c(x) Q0_c |u_c(x)| with the
friction coefficient and sliding speed of design x (`frozen_friction_integrands`), a plain time
average (C = 1 per saved state).
"""

from __future__ import annotations

import dataclasses

import diffrax
import jax
import jax.numpy as jnp
import numpy as np

from .._errors import UserInputError
from ..contact import LOAD_FLOOR
from ..dynamics import Params, State, contact_loads
from ..flange import DesignVariables
from ..geometry import Bearing, OperatingPoint
from ..io import require
from ..run import (
    CONTACT_THRESHOLD,
    STRATEGIES,
    TAIL_LEVEL,
    checks_without_host_callbacks,
    choose_strategy,
    compiled_program,
    map_members,
    prepare_from,
    result_code,
    scaled_diffeqsolve,
    stack_trees,
)
from ._design import forward_jacobian
from ._steady_objective import (
    FRICTION_REFERENCE,
    STEADY_FUNCTIONALS,
    Statistic,
    SteadyGradient,
    _check_window,
    _combine,
    _design_params,
    _failed_integrals,
    _functionals,
    statistic_of,
)


def trajectory_states(
    bearing, op, start: State, duration: float, num_saves: int, *, rtol=1e-3, atol=1e-6, max_steps=400_000
):
    """The physical states at `num_saves` equally spaced times in (0, duration] of a plain
    solve from `start` (a State with a leading time axis on every leaf)."""
    params = Params(bearing=bearing, operating=op, functionals=STEADY_FUNCTIONALS)
    scaling, args, y0, controller = prepare_from(
        params, jax.tree_util.tree_map(jnp.asarray, start), rtol, atol
    )
    ts = jnp.linspace(0.0, duration, num_saves + 1)[1:]
    saveat = diffrax.SaveAt(ts=ts, fn=lambda t, y, a: a.scaling.unscale(t, y))
    with checks_without_host_callbacks():
        sol = scaled_diffeqsolve(y0, args, duration, saveat, controller, max_steps, None, False)
    return sol.ys, result_code(sol.result)


def _reference_loads(bearing, op, x, states):
    """The flange contact loads Q0 (T, Z, 4) the dynamics gave at the saved `states` (a leading
    time axis) of design x: the loads the frozen-load estimator holds."""
    return jax.vmap(lambda s: contact_loads(s, _design_params(bearing, op, x)).flange.normal_force)(states)


def frozen_pv(bearing, op, x, state: State, reference_load):
    """(w(Q0_c), PV_c(x) (Q0_c / Q_c(x))^(1/3) / PV_ref), each (Z, 4), over the flange contacts of
    one state: the flange PV with design x at the loads Q0 = `reference_load` (Z, 4) the
    dynamics gave (module docstring, frozen-load estimator), and the smooth contact indicator.
    Hertz: p_max = c(radii) Q^(1/3), so PV (Q0/Q)^(1/3) is the PV at load Q0 with the contact
    point, curvatures and sliding velocity of design x."""
    fl = contact_loads(state, _design_params(bearing, op, x)).flange
    q0 = reference_load
    on = (q0 > LOAD_FLOOR) & (fl.normal_force > LOAD_FLOOR)
    safe_q = jnp.where(on, fl.normal_force, 1.0)
    ratio = jnp.where(on, (jnp.where(on, q0, 1.0) / safe_q) ** (1.0 / 3.0), 0.0)
    w = q0 / (q0 + STEADY_FUNCTIONALS.contact_load)
    return w, fl.pv * ratio / STEADY_FUNCTIONALS.pv_reference


def frozen_load_integrands(bearing, op, x, state: State, reference_load, exponent=1.0):
    """(sum_c w(Q0_c) (PV_c(x) (Q0_c / Q_c(x))^(1/3) / PV_ref)^p, sum_c w(Q0_c)) over the flange
    contacts of one state, p = `exponent` (`frozen_pv`)."""
    w, frozen = frozen_pv(bearing, op, x, state, reference_load)
    return jnp.stack([jnp.sum(w * frozen**exponent), jnp.sum(w)])


def frozen_friction_integrands(bearing, op, x, state: State, reference_load):
    """(sum_c mu_c(x) Q0_c |u_c(x)| / P_ref, 1) over the flange contacts of one state: the total
    flange friction power [W / P_ref] with design x at the loads Q0 = `reference_load` (Z, 4)
    the dynamics gave, with the friction coefficient and the material sliding speed of design x
    at the contact point of design x (docs/model.md 5.5). mu is evaluated at the design's own
    load Q(x): its dependence on the load through the film parameter (h_min ~ Q^-0.073) is
    left out of the frozen estimate. The second entry is the time average's weight: every
    saved state counts once."""
    fl = contact_loads(state, _design_params(bearing, op, x)).flange
    q0 = jnp.where(reference_load > LOAD_FLOOR, reference_load, 0.0)
    power = fl.friction_coefficient * q0 * fl.sliding_speed
    return jnp.stack([jnp.sum(power) / FRICTION_REFERENCE, jnp.ones((), power.dtype)])


def frozen_tail_samples(bearing, op, x, states):
    """The tail statistic's samples along one trajectory (`states`: a leading time axis): per
    saved state and flange contact, the statistics' hard contact indicator 1(Q0 > 1 N), the
    frozen PV / PV_ref at x (`frozen_pv`) and its Jacobian in x (leading axis 3)."""
    q0 = _reference_loads(bearing, op, x, states)
    pv, dpv = forward_jacobian(
        lambda v: jax.vmap(lambda s, q: frozen_pv(bearing, op, v, s, q)[1])(states, q0), x
    )
    return (q0 > CONTACT_THRESHOLD).astype(float), pv, dpv


def tail_integrals(samples, num_variables: int = 3) -> tuple[list, float]:
    """The tail statistic's per-trajectory integrals from `frozen_tail_samples` of every
    trajectory of one design ((w, pv, dpv) each, or None for a failed one): q, the 95th
    percentile of the frozen PV / PV_ref over every touching sample, and per trajectory
    ((A, C), Jacobian (3, 2)) with A = sum w (pv - q)^+, C = sum w, dA = sum w 1(pv > q) dpv
    (the Rockafellar-Uryasev form at fixed q, `_steady_objective`'s tail statistic). Returns (outs, q)."""
    touching = [np.asarray(pv)[np.asarray(w) > 0.5] for w, pv, _ in filter(None, samples)]
    pooled = np.concatenate(touching) if touching else np.zeros(0)
    if pooled.size == 0:
        return [_failed_integrals(num_variables) for _ in samples], float("nan")
    q = float(np.percentile(pooled, 100.0 * TAIL_LEVEL))
    outs = []
    for sample in samples:
        if sample is None:
            outs.append(_failed_integrals(num_variables))
            continue
        w, pv, dpv = (np.asarray(a) for a in sample)
        above = w * (pv > q)
        a = float(np.sum(w * np.maximum(pv - q, 0.0)))
        da = np.sum(above[None] * dpv, axis=tuple(range(1, dpv.ndim)))
        outs.append((np.array([a, float(np.sum(w))]), np.stack([da, np.zeros_like(da)], axis=1)))
    return outs, q


@dataclasses.dataclass(frozen=True)
class _FrozenSample:
    """Picklable frozen-load samples along one trajectory (`parallel_map`): the trajectory
    integrated once, then per statistic of `statistics` its integrals and Jacobian (the mean and
    the peak: `_frozen_jacobian`, at the statistic's exponent) or its samples (the tail:
    `frozen_tail_samples`)."""

    bearing: Bearing
    op: OperatingPoint
    x: np.ndarray
    duration: float
    num_saves: int
    rtol: float
    statistics: tuple = ("mean",)

    def __call__(self, state) -> dict:
        x = jnp.asarray(self.x)
        state = jax.tree_util.tree_map(jnp.asarray, state)
        num_saves = self.num_saves
        args = (self.bearing, self.op, state, jnp.asarray(self.duration), jnp.asarray(self.rtol))
        trajectory = lambda b, o, s, d, r: trajectory_states(b, o, s, d, num_saves, rtol=r)
        states, code = compiled_program("trajectory_states", trajectory, args, num_saves)(*args)
        if int(code) != 0:  # a failed trajectory: no samples (tail), NaN integrals (sums)
            return {s: _failed_sample(s, len(self.x)) for s in self.statistics}
        out = {}
        for statistic in self.statistics:
            if statistic == "tail":
                args = (self.bearing, self.op, x, states)
                program = compiled_program("frozen_tail_samples", frozen_tail_samples, args)
                out[statistic] = tuple(map(np.asarray, program(*args)))
            elif statistic == "friction":
                args = (self.bearing, self.op, x, states)
                val, jac = compiled_program("frozen_friction_jacobian", _friction_jacobian, args)(*args)
                out[statistic] = (np.asarray(val), np.asarray(jac))
            else:
                args = (self.bearing, self.op, x, states, _exponent(statistic))
                val, jac = compiled_program("frozen_load_jacobian", _frozen_jacobian, args)(*args)
                out[statistic] = (np.asarray(val), np.asarray(jac))
        return out


def _exponent(statistic: str) -> np.float64:
    """The PV exponent p of a statistic's frozen-load integrand (`STATISTICS`)."""
    return np.float64(_functionals(statistic).pv_exponent)


def _failed_sample(statistic: str, num_variables: int = 3):
    """A failed trajectory's sample: no tail samples (None), NaN integrals otherwise."""
    return None if statistic == "tail" else _failed_integrals(num_variables)


def _summed_jacobian(integrand, bearing, op, x, states):
    """Sum over the saved `states` of `integrand(v, state, Q0)` (design v, the loads Q0 the
    dynamics gave at that state, `_reference_loads`) and its Jacobian in x: what every
    frozen-load statistic but the tail sums along a trajectory."""
    q0 = _reference_loads(bearing, op, x, states)

    def total(v):
        return jnp.sum(jax.vmap(lambda s, q: integrand(v, s, q))(states, q0), axis=0)

    return forward_jacobian(total, x)


def _frozen_jacobian(bearing, op, x, states, exponent=1.0):
    """Sum over the saved states of the frozen-load PV integrands (`frozen_load_integrands`)
    and their Jacobian in x."""
    pv = lambda v, s, q: frozen_load_integrands(bearing, op, v, s, q, exponent)
    return _summed_jacobian(pv, bearing, op, x, states)


def _friction_jacobian(bearing, op, x, states):
    """Sum over the saved states of the frozen friction integrands (`frozen_friction_integrands`)
    and their Jacobian in x."""
    friction = lambda v, s, q: frozen_friction_integrands(bearing, op, v, s, q)
    return _summed_jacobian(friction, bearing, op, x, states)


def frozen_load_gradient(
    bearing: Bearing, op: OperatingPoint, design: DesignVariables, states, **options
) -> SteadyGradient:
    """The frozen-load estimate (module docstring) of the steady objective and its gradient at
    `design` from `states`: `frozen_load_gradients` of this one case, with its `options`."""
    return frozen_load_gradients([(bearing, op, design, states)], **options)[0]


def frozen_load_gradients(
    cases, *, statistic: Statistic | str = Statistic.MEAN, **options
) -> list[SteadyGradient]:
    """The frozen-load estimate (module docstring) of the steady objective and its gradient for
    every case (bearing, op, design, states), e.g. every start and operating point of one
    iteration of the design search; one `SteadyGradient` per case, in order. `statistic`:
    "mean" (PV over contact time), "peak" (its p-mean), "tail" (the mean of its worst 5 %) or
    "friction" (the time-mean total flange friction power);
    the other `options` and how the trajectories run: `frozen_load_statistics`, of this one
    statistic."""
    key = statistic_of(statistic)
    return [found[key] for found in frozen_load_statistics(cases, statistics=(key,), **options)]


def frozen_load_statistics(
    cases,
    *,
    statistics=("mean", "peak", "tail", "friction"),
    window: float = 1.0e-3,
    saves_per_ms: int = 200,
    rtol: float = 1e-3,
    workers: int = 1,
    strategy: str = "auto",
) -> list[dict[str, SteadyGradient]]:
    """The frozen-load estimates (module docstring) of the steady objective and its gradient for
    every case (bearing, op, design, states) and every statistic of `statistics`: one
    {statistic: `SteadyGradient`} per case, in order. From each of a case's `states` (states of
    settled running of that design), a plain solve with `design` applied to `bearing` (its other
    parameters kept) over `window` seconds saves the state every 1 / `saves_per_ms` ms; at every
    saved state the flange PV is differentiated in the design at the loads the dynamics gave
    (`frozen_load_integrands`), summed, and combined through the ratio estimator; jackknife over
    the trajectories. Each trajectory is integrated once for all the statistics: they differ
    only in what is summed over its saved states. Statistics (`STATISTICS`): "mean" (PV over
    contact time), "peak" (its p-mean), "tail" (the mean of its worst 5 %, at the 95th
    percentile of the trajectories' own touching samples: `tail_integrals`) or "friction" (the
    time-mean total flange friction power: `frozen_friction_integrands`). Every trajectory
    of every case is one member of one call (`strategy`, as the steady-running engine's
    `choose_strategy`): "vmap" (the default on an accelerator) integrates and differentiates
    them all in one vmapped program; on a CPU they run `workers` processes at a time
    ("processes"), or one after another ("sequential")."""
    _check_window(window)
    require("saves_per_ms", saves_per_ms, lambda v: (v >= 1) & (v == np.round(v)), "an integer >= 1")
    if strategy not in STRATEGIES:
        raise UserInputError(f"strategy = {strategy!r}: must be one of {', '.join(map(repr, STRATEGIES))}")
    statistics = tuple(
        dict.fromkeys(statistic_of(s) for s in ([statistics] if isinstance(statistics, str) else statistics))
    )
    if not statistics:
        raise UserInputError("statistics = (): must name at least one of 'mean', 'peak', 'tail', 'friction'")
    cases = list(cases)
    n = max(1, int(round(window * 1e3 * saves_per_ms)))
    jobs, owner = [], []
    for k, (bearing, op, design, states) in enumerate(cases):
        x = np.asarray(design.as_array(), dtype=float)
        # the trajectories run with the design, as the settled states did: a bearing of another
        # design would start every window off its contacts (micrometres against a changed end arc)
        job = _FrozenSample(design.apply(bearing), op, x, float(window), n, float(rtol), statistics)
        jobs += [(job, s) for s in states]
        owner += [k] * len(states)
    outs = _run_frozen(jobs, strategy, workers)
    per_case = [[o for o, j in zip(outs, owner) if j == k] for k in range(len(cases))]
    sizes = [int(np.size(design.as_array())) for _, _, design, _ in cases]
    return [
        {s: _combine_statistic(s, [o[s] for o in per], window, n) for s in statistics}
        for per, n in zip(per_case, sizes)
    ]


def _combine_statistic(statistic: str, samples: list, window: float, num_variables: int) -> SteadyGradient:
    """One statistic's estimate from its per-trajectory samples (`_FrozenSample`): the ratio
    estimator at its exponent (mean, peak), as a plain time average (friction), or at the tail
    threshold of its samples (tail)."""
    if statistic != "tail":
        return _combine(
            samples,
            window,
            float(_exponent(statistic)),
            num_variables=num_variables,
            reference=statistic_of(statistic).reference,
        )
    integrals, q = tail_integrals(samples, num_variables)
    return _combine(
        integrals, window, tail_threshold=q * STEADY_FUNCTIONALS.pv_reference, num_variables=num_variables
    )


def _run_frozen(jobs, strategy: str, workers: int) -> list:
    """The outputs of every (`_FrozenSample`, state) of `jobs`, in order, by `strategy`
    (`choose_strategy`) through the engine's member dispatcher (`run.map_members`): one vmapped
    program ("vmap", `_frozen_samples_batched`), `workers` processes ("processes") or one after
    another in this process ("sequential")."""
    chosen = choose_strategy(strategy, min(int(workers), max(1, len(jobs))))
    return map_members(jobs, chosen, workers, _frozen_job, _frozen_samples_batched)


def _frozen_job(item):
    """One (`_FrozenSample`, state) of `frozen_load_gradients` (picklable for `parallel_map`)."""
    job, state = item
    return job(state)


def _frozen_samples_batched(jobs) -> list:
    """Every (`_FrozenSample`, state) of `jobs` as one member of one vmapped program: its
    trajectory, integrated once, and per statistic the frozen-load integrals and Jacobian (mean,
    peak: their exponents a traced argument, so one program serves either; friction) or the
    tail's samples."""
    num_saves, statistics = jobs[0][0].num_saves, jobs[0][0].statistics
    sums = [s for s in statistics if s != "tail"]
    tail = "tail" in statistics

    def one(b, o, x, s, d, r, p):
        states, code = trajectory_states(b, o, s, d, num_saves, rtol=r)
        out = [
            _friction_jacobian(b, o, x, states)
            if name == "friction"
            else _frozen_jacobian(b, o, x, states, p[i])
            for i, name in enumerate(sums)
        ]
        return (out, frozen_tail_samples(b, o, x, states) if tail else None), code

    args = stack_trees(
        [
            (
                job.bearing,
                job.op,
                jnp.asarray(job.x),
                state,
                np.float64(job.duration),
                np.float64(job.rtol),
                np.array([_exponent(s) for s in sums], dtype=np.float64),
            )
            for job, state in jobs
        ]
    )
    program = compiled_program("frozen_members", jax.vmap(one), args, (num_saves, tuple(sums), tail))
    (sum_outs, tail_outs), codes = jax.device_get(program(*args))
    found = []
    for i in range(len(jobs)):
        ok = int(codes[i]) == 0
        one_member = {s: (sum_outs[j][0][i], sum_outs[j][1][i]) for j, s in enumerate(sums)}
        if tail:
            one_member["tail"] = tuple(a[i] for a in tail_outs)
        found.append({s: one_member[s] if ok else _failed_sample(s, len(jobs[i][0].x)) for s in statistics})
    return found
