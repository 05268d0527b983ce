"""Which unknown inputs matter: the effect of each uncertain input on settled statistics
(docs/model.md 18).

Inputs. Every key of the configuration's `[uncertainty]` table (`Config.uncertainty`: estimated
or user-marked values, each with its half-width u), and the model's own representative constants
(`MODEL_CONSTANTS`: the traction curve A-D and the oil fraction, with stated default half-widths)
unless the table already gives them. The drag coefficient is not a configuration key (White's fit
C_d(Re), forces/_drag.py); the drag force is proportional to the oil-air mixture's density and
therefore to the oil fraction, whose entry carries that uncertainty.

Effect. For a statistic S and an input x with half-width u, the effect is

    E = (dS/dx) u,

the change of S over the input's stated uncertainty to first order; inputs are ranked by |E|.

Methods (`METHODS`), chosen per statistic:

- "crn" (every statistic): common-random-number central differences of settled ensembles. For
  each input, two settled runs x + h and x - h with h = u (the secant across the stated range;
  halved while x +/- h leaves the key's valid range) and the same seeds, hence the same seeded
  roller scatter; each seed k gives D_k = (S_k(x + h) - S_k(x - h)) / 2h
  (`paired_central_difference`), and dS/dx is their mean with the Student-t 95 % interval over
  the seeds. The seed's own scatter cancels in each difference, the model's chaotic
  roller-flange impacts do not: the interval says how well the seeds resolved the derivative.
  The frozen-load estimator (`frozen_load_gradient`) is not used: it differentiates flange PV in
  the three roller-end/flange design variables at the loads the dynamics gave, and the inputs
  here (traction, oil fraction, masses, dimensions) act through those very loads and speeds.
- "static" (cage slip only; `--quick`): central differences of the cage slip of the static skid
  equilibrium (`dynamics.skid_equilibrium`: the cage and roller speeds at which the slow
  accelerations of the dynamic model vanish, docs/model.md 16), deterministic and cheap (one
  equilibrium solve per evaluation). dS/dx is the difference D(u) at h = u, the same secant as
  the "crn" method's; its interval +/- |D(u) - D(u/2)| u says how far the cage slip departs
  from a straight line over the stated range (for a smooth S it bounds the secant's distance
  from the derivative), not a statistical interval. The static balance leaves out the flanges'
  friction once the rollers skew (it lies 1.4 % above the settled cage speed at the reference
  point), so it ranks the inputs of the cage slip; the settled value is the "crn" method's.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Callable, Mapping, Sequence

from .._errors import ConfigError, UserInputError
from ..dynamics import Params, skid_equilibrium
from ..geometry import kinematic_cage_speed
from ..io import KEY_BY_PATH, Config, Uncertainty
from ..run import (
    Perturbation,
    SettledStatistics,
    SteadySettings,
    compiled_program,
    initial_state,
    settled_statistics,
    simulate_steady_points,
)
from ._steady_objective import paired_central_difference


@dataclasses.dataclass(frozen=True)
class Statistic:
    """A settled statistic a sensitivity study ranks the inputs by: its name on the command
    line, label, SI unit, the factor and unit it is printed in, and the field it is read from
    in a seed's statistics (`run.SettledStatistics`)."""

    name: str
    label: str
    unit: str
    shown_factor: float
    shown_unit: str
    read: Callable[[SettledStatistics], float]


#: the statistics of `sensitivity`, per cage revolution of settled running
STATISTICS = {
    s.name: s
    for s in (
        Statistic("cage_slip", "cage slip", "1", 100.0, "%", lambda s: s.cage_slip.value),
        Statistic(
            "mean_pv", "mean flange PV", "Pa m/s", 1e-9, "GPa m/s", lambda s: s.flange_pv_Pa_m_s.mean.value
        ),
        Statistic(
            "peak_pv", "peak flange PV", "Pa m/s", 1e-9, "GPa m/s", lambda s: s.flange_pv_Pa_m_s.max.value
        ),
        Statistic(
            "contact_height", "largest contact height", "m", 1e3, "mm", lambda s: s.contact_height_m.max.value
        ),
    )
}
#: the methods (module docstring): settled CRN central differences, static skid equilibrium
METHODS = {
    "crn": "common-random-number central differences of settled ensembles (same seeds), h = u; "
    "95 % Student-t interval over the seeds",
    "static": "central differences of the static skid equilibrium's cage slip, h = u; "
    "interval +/- |D(u) - D(u/2)| u (departure from a straight line over the range; deterministic)",
}

#: the model's representative constants and their default half-widths u (in the key's unit) with
#: the reason: the traction curve is the source paper's fit for one oil (docs/model.md 5), so a
#: quarter of each constant; the oil fraction of the oil-air mixture in the cavity is rarely
#: known better than a factor of about 1.5-2 (it sets the drag and churning, and the drag
#: coefficient's uncertainty with them), so half of the reference 0.05
MODEL_CONSTANTS = {
    "lubricant.traction_a": (0.01, "traction curve fitted for one oil: +/- 25 % of the reference -0.04"),
    "lubricant.traction_b_s_m": (
        0.063,
        "traction curve fitted for one oil: +/- 25 % of the reference 0.2528",
    ),
    "lubricant.traction_c_s_m": (0.73, "traction curve fitted for one oil: +/- 25 % of the reference 2.926"),
    "lubricant.traction_d": (0.01, "traction curve fitted for one oil: +/- 25 % of the reference 0.04"),
    "lubricant.oil_fraction": (
        0.025,
        "oil-air fraction rarely known within a factor 1.5-2: +/- half of the reference 0.05 "
        "(also carries the drag coefficient's uncertainty: drag scales with the mixture density)",
    ),
}
#: halvings of the step tried while x +/- h leaves the key's valid range
_STEP_HALVINGS = 6


@dataclasses.dataclass(frozen=True)
class SensitivityInput:
    """One uncertain input: its key, value, half-width u (key's unit), where u comes from
    ("estimated", "uncertain": the `[uncertainty]` table; "model constant": `MODEL_CONSTANTS`)
    and the rule or reason."""

    key: str
    value: float
    plus_minus: float
    source: str
    reason: str = ""


@dataclasses.dataclass(frozen=True)
class Effect:
    """The effect E = (dS/dx) u of one input on one statistic, with its 95 % interval, the
    derivative it came from, the method (`METHODS`), the step h used and the seeds n (1 for
    "static")."""

    effect: float
    ci95_low: float
    ci95_high: float
    derivative: float
    method: str
    step: float
    n: int

    def to_dict(self) -> dict:
        return dataclasses.asdict(self)


@dataclasses.dataclass(frozen=True)
class Sensitivity:
    """The inputs, the statistics and the effect of every input on every statistic
    (`effects[statistic][i]` belongs to `inputs[i]`), the settings of the settled runs."""

    inputs: tuple[SensitivityInput, ...]
    statistics: tuple[str, ...]
    effects: Mapping[str, tuple[Effect, ...]]
    seeds: int
    window_revs: float
    num_slices: int

    def ranking(self, statistic: str) -> list[int]:
        """Indices of `inputs` by |effect| on `statistic`, largest first (NaN last)."""
        e = [abs(x.effect) if math.isfinite(x.effect) else -1.0 for x in self.effects[statistic]]
        return sorted(range(len(e)), key=lambda i: -e[i])

    def to_dict(self) -> dict:
        """Data only: inputs, per statistic the effects (inputs' order) and the ranking (keys)."""
        return {
            "seeds": self.seeds,
            "window_revs": self.window_revs,
            "num_slices": self.num_slices,
            "methods": {m: METHODS[m] for m in sorted({e.method for v in self.effects.values() for e in v})},
            "inputs": [dataclasses.asdict(i) for i in self.inputs],
            "statistics": {
                s: {
                    "label": STATISTICS[s].label,
                    "unit": STATISTICS[s].unit,
                    "effects": {i.key: e.to_dict() for i, e in zip(self.inputs, self.effects[s])},
                    "ranking": [self.inputs[i].key for i in self.ranking(s)],
                }
                for s in self.statistics
            },
        }


def parse_statistics(names: str | Sequence[str]) -> tuple[str, ...]:
    """The statistics of a comma-separated list (or a sequence), each checked (one line)."""
    items = [n.strip() for n in names.split(",")] if isinstance(names, str) else list(names)
    for n in items:
        if n not in STATISTICS:
            raise UserInputError(f"statistics = {n!r}: must be one of {', '.join(STATISTICS)}")
    if not items:
        raise UserInputError(f"statistics: none given; choose from {', '.join(STATISTICS)}")
    return tuple(dict.fromkeys(items))


def sensitivity_inputs(cfg: Config, model_constants: bool = True) -> tuple[SensitivityInput, ...]:
    """The uncertain inputs of `cfg`: its `[uncertainty]` table's keys, then (with
    `model_constants`) the `MODEL_CONSTANTS` the table does not name; keys with u = 0 are left
    out. A configuration with neither is an error (one line)."""
    table: dict[str, Uncertainty] = dict(cfg.uncertainty)
    out = [
        SensitivityInput(
            k, float(cfg[k]), float(u.plus_minus), "estimated" if u.estimated else "uncertain", u.estimated
        )
        for k, u in table.items()
        if u.plus_minus > 0
    ]
    if model_constants:
        out += [
            SensitivityInput(k, float(cfg[k]), u, "model constant", why)
            for k, (u, why) in MODEL_CONSTANTS.items()
            if k not in table
        ]
    if not out:
        raise UserInputError(
            "uncertainty: the configuration has no [uncertainty] entry with plus_minus > 0 and the model's "
            "constants are left out; nothing to rank"
        )
    return tuple(out)


def perturbed(cfg: Config, item: SensitivityInput, step: float) -> tuple[float, Config, Config]:
    """(h, cfg with x + h, cfg with x - h): the step `step` halved while either leaves the key's
    valid range (`ConfigError`); integer keys step by whole numbers >= 1. One line when no step
    fits."""
    integer = KEY_BY_PATH[item.key].kind is int
    h = float(max(1, round(step))) if integer else float(step)
    for _ in range(_STEP_HALVINGS + 1):
        try:
            up = cfg.replace({item.key: _typed(item.value + h, integer)})
            down = cfg.replace({item.key: _typed(item.value - h, integer)})
            return h, up, down
        except ConfigError:
            if integer:
                break
            h /= 2
    raise UserInputError(
        f'uncertainty."{item.key}": {item.key} = {item.value:g} +/- {step:g} leaves its valid range '
        "even for the smallest step tried; give a smaller plus_minus"
    )


def _typed(v: float, integer: bool):
    return int(round(v)) if integer else float(v)


# -- the static skid equilibrium ------------------------------------------------------------------
def _static_slip(bearing, op):
    """Cage slip (omega_kin - omega_c) / omega_kin of the static skid equilibrium at the seeded
    default start (`run.initial_state` with `Perturbation()`); pure, compiled once."""
    start = initial_state(bearing, op, Perturbation())
    kin = kinematic_cage_speed(bearing, op)
    eq = skid_equilibrium(start, Params(bearing=bearing, operating=op), kin)
    return (kin - eq.cage_speed) / kin


def static_cage_slip(cfg: Config) -> float:
    """The cage slip of `cfg`'s static skid equilibrium (module docstring, "static")."""
    b, op = cfg.bearing(), cfg.operating_point()
    return float(compiled_program("sensitivity_static_slip", _static_slip, (b, op))(b, op))


def static_effect(cfg: Config, item: SensitivityInput) -> Effect:
    """The "static" effect of `item` on the cage slip (module docstring): D(u) u, interval
    +/- |D(u) - D(u/2)| u."""
    h, up, down = perturbed(cfg, item, item.plus_minus)
    d_full = (static_cage_slip(up) - static_cage_slip(down)) / (2 * h)
    h2, up2, down2 = perturbed(cfg, item, h / 2)
    d_half = (static_cage_slip(up2) - static_cage_slip(down2)) / (2 * h2)
    u = item.plus_minus
    e, err = d_full * u, abs(d_full - d_half) * u
    return Effect(e, e - err, e + err, d_full, "static", h, 1)


# -- CRN central differences of settled ensembles -------------------------------------------------
def _per_seed(result) -> dict[int, SettledStatistics]:
    """{seed: the statistics of that seed's window alone} of a `SteadyResult`."""
    out = {}
    for r in result.runs:
        if r.measured and r.window:
            out[r.seed] = settled_statistics([r.window], [r.edges], result.bearing, result.operating)
    return out


def crn_effects(
    cfg: Config, inputs: Sequence[SensitivityInput], statistics: Sequence[str], settings: SteadySettings
) -> dict[str, list[Effect]]:
    """The "crn" effects of every input on every statistic: the settled runs x +/- h of all
    inputs are the points of one call of the steady-running engine (`simulate_steady_points`),
    every point with the seeds 0 .. settings.seeds - 1 (module docstring)."""
    from scipy import stats

    steps, bearings, ops = [], [], []
    for item in inputs:
        h, up, down = perturbed(cfg, item, item.plus_minus)
        steps.append(h)
        for c in (up, down):
            bearings.append(c.bearing())
            ops.append(c.operating_point())
    results = simulate_steady_points(bearings, ops, settings)
    out: dict[str, list[Effect]] = {s: [] for s in statistics}
    for i, item in enumerate(inputs):
        plus, minus = _per_seed(results[2 * i]), _per_seed(results[2 * i + 1])
        seeds = sorted(set(plus) & set(minus))
        for s in statistics:
            read = STATISTICS[s].read
            d, se, n = paired_central_difference(
                [read(plus[k]) for k in seeds], [read(minus[k]) for k in seeds], steps[i]
            )
            half = float(stats.t.ppf(0.975, n - 1)) * se if n > 1 else float("nan")
            u = item.plus_minus
            out[s].append(Effect(d * u, (d - half) * u, (d + half) * u, d, "crn", steps[i], n))
    return out


def sensitivity(
    cfg: Config,
    statistics: Sequence[str] = tuple(STATISTICS),
    settings: SteadySettings | None = None,
    *,
    quick: bool = False,
    model_constants: bool = True,
) -> Sensitivity:
    """The effect of every uncertain input of `cfg` (`sensitivity_inputs`) on each of
    `statistics` (`STATISTICS`), module docstring. `quick`: the cage slip alone, by the static
    skid equilibrium ("static"), no dynamic run; otherwise every statistic by CRN central
    differences of settled runs with `settings` (seeds, window; default `SteadySettings()`),
    (the "crn" method)."""
    statistics = parse_statistics(statistics)
    if quick and statistics != ("cage_slip",):
        others = ", ".join(s for s in statistics if s != "cage_slip")
        raise UserInputError(
            f"statistics = {others}: the quick study (static skid equilibrium) gives the cage slip only; "
            "leave out --quick for settled statistics"
        )
    settings = settings if settings is not None else SteadySettings()
    inputs = sensitivity_inputs(cfg, model_constants)
    effects: dict[str, tuple[Effect, ...]] = {}
    if quick:
        effects["cage_slip"] = tuple(static_effect(cfg, i) for i in inputs)
    else:
        effects.update({s: tuple(v) for s, v in crn_effects(cfg, inputs, statistics, settings).items()})
    return Sensitivity(
        inputs=inputs,
        statistics=statistics,
        effects=effects,
        seeds=0 if quick else settings.seeds,
        window_revs=0.0 if quick else float(settings.window_revs),
        num_slices=int(cfg["bearing.num_slices"]),
    )
