"""How the design search on steady running measures its objective and constraints: one
settings object, `SteadySettings`, checked once when built (one line naming the setting).

Lengths in metres, the gradient window in seconds, the settling time in ms. The search measures
each evaluation with fewer seeds and revolutions than a settled run of `jaxbearing simulate`
(4 seeds x 2 revolutions: an evaluation per start, operating point and iteration) and verifies
with more on seeds it never used; `SteadySettings.measurement()` turns these fields into the one
settings object of settled running (`jaxbearing.run.SteadySettings`), which the design metrics
take.
"""

from __future__ import annotations

import dataclasses
import enum

import jax
import numpy as np

from jaxbearing import UserInputError, run
from jaxbearing.design import CORNER_MARGIN, Statistic
from jaxbearing.io import require
from jaxbearing.run import available_cpus

from ._problem import DesignProblem


class Estimator(enum.StrEnum):
    """How the search estimates the gradient of the steady objective: `FROZEN` (the frozen-load
    estimate, `jaxbearing.design.frozen_load_gradients`) or `WINDOW` (short-window forward-mode
    sensitivities, `jaxbearing.design.steady_gradient`). The value is the command line's name."""

    FROZEN = "frozen"
    WINDOW = "window"


class CornerConstraint(enum.StrEnum):
    """The statistic of the per-revolution largest contact radius the dynamic corner constraint
    keeps inside the limited circle (`SteadySettings.corner_constraint`, docs/model.md 17):
    `RISK` (the normal tolerance bound that one revolution exceeds with probability
    `corner_risk_level` at most, at 95 % confidence: the corner-contact risk's upper bound below
    the level), `PREDICTION` (the upper 95 % prediction bound of one further revolution) or
    `MEAN` (its expectation per revolution)."""

    RISK = "risk"
    PREDICTION = "prediction"
    MEAN = "mean"


class Choice(enum.StrEnum):
    """Which of the statistically tied feasible designs the search returns: `SAFEST` (the one of
    the lowest corner-risk bound) or `BEST` (the lowest upper 95 % bound of the objective)."""

    SAFEST = "safest"
    BEST = "best"


#: the names of the choices, as the command line and the TOML files give them
ESTIMATORS = tuple(e.value for e in Estimator)
#: a point left out of the envelope's active set still runs while its corner margin is below
#: this [m] (`next_active`): one step of the default search moved the limited-circle margin by
#: up to 0.25 mm and the dynamic corner margin by up to 0.28 mm (results/optimise_steady_default_run.json),
#: so a margin above it does not bind within a step. Without it, margins alike at every speed
#: kept every point running (benchmarks/results/bench_envelope_active_set.json)
CORNER_WATCH = 0.3e-3
CORNER_CONSTRAINTS = tuple(c.value for c in CornerConstraint)
CHOICES = tuple(c.value for c in Choice)


def _member(kind: type[enum.StrEnum], name: str, value):
    """`value` (a member of `kind`, or its name as text) as a member of `kind`, or a one-line
    error naming the setting and the valid names: the one place text maps to the choices."""
    try:
        return kind(value)
    except ValueError:
        raise UserInputError(
            f"{name} = {value!r}: must be one of {', '.join(repr(m.value) for m in kind)}"
        ) from None


#: `clearance_step="auto"` gives the search a signal for Delta_bf where an operating point is
#: misaligned by more than this [rad]: the clearance study (docs/model.md 17) found dJ/dDelta_bf
#: clearly significant at 2 mrad (+2.5 % of J per 10 um at 100 mm / 1.4 deg) and bounded near 0
#: at 1 mrad at both designs (within -0.4 .. +0.4 % of J per 10 um)
CLEARANCE_MISALIGNMENT = 1.0e-3
#: ... with this half-step [m] (the study's h)
CLEARANCE_STEP = 0.01e-3


def clearance_step_for(problem: DesignProblem, settings: SteadySettings) -> float:
    """The half-step h [m] of the search's Delta_bf difference: `settings.clearance_step`, or
    with "auto", `CLEARANCE_STEP` where any operating point of `problem` is misaligned by more
    than `CLEARANCE_MISALIGNMENT` and 0 (off: three times the members for a slope the study
    bounds near 0) elsewhere."""
    if not isinstance(settings.clearance_step, str):
        return float(settings.clearance_step)
    tilt = np.max(np.abs(np.asarray(problem.operating.misalignment, dtype=float)))
    return CLEARANCE_STEP if tilt > CLEARANCE_MISALIGNMENT * (1 + 1e-9) else 0.0


@dataclasses.dataclass(frozen=True)
class SteadySettings:
    """How the steady objective of the design search is measured (module docstring)."""

    seeds: int = 4
    window_revs: int = 2
    settle: object = "auto"
    gradient_window: float = 1.0e-3
    estimator: Estimator = Estimator.FROZEN
    corner_margin: float = CORNER_MARGIN
    rtol: float = 1e-3
    workers: int = 0  # 0: one per CPU
    verify_seeds: int = 4
    verify_first_seed: int = 1000
    verify_window_revs: int = 4
    #: the statistic minimised (`jaxbearing.design.Statistic`): of flange PV the mean over
    #: contact time, the peak (its p-mean) or the tail (the mean of its worst 5 %); or the
    #: time-mean total flange friction power (objective in W)
    statistic: Statistic = Statistic.MEAN
    #: half-step of the common-random-number central difference in Delta_bf [m] (0: off), or
    #: "auto": `CLEARANCE_STEP` where the envelope is misaligned by more than
    #: `CLEARANCE_MISALIGNMENT`, else off (`clearance_step_for`); the frozen-load estimator
    #: cannot see the clearance (`evaluate_starts`)
    clearance_step: float | str = "auto"
    #: the dynamic corner constraint (`CornerConstraint`; `RISK`: the normal tolerance bound of
    #: the per-revolution largest contact radius, `run.tolerance_bound`)
    corner_constraint: CornerConstraint = CornerConstraint.RISK
    #: the corner-contact risk per cage revolution the search keeps below at every operating
    #: point ("risk" constraint) and the verification must bound (its upper 95 % bound,
    #: `run.corner_risk`), else the design is reported unverified in the tail
    #: (`tail_verification`)
    corner_risk_level: float = 1e-3
    #: the design returned among the statistically tied feasible ones (`Choice`)
    choose: Choice = Choice.SAFEST
    #: the envelope's active set (`next_active`): an operating point whose weight in the smooth
    #: max stays below this is not simulated (0: every point, every iteration) ...
    skip_weight: float = 1e-3
    #: ... for at most this many iterations in a row
    recheck_every: int = 3
    #: the film parameter the design must keep (None: no limit): the lower 95 % bound of the
    #: 5th percentile of Lambda over contact time >= this at every operating point
    min_film_parameter: float | None = None
    #: the flash temperature rise at the rib the design must stay under [K] (None: no limit):
    #: the upper 95 % bound of a revolution's largest rise (its mean per revolution) <= this
    max_flash_temperature: float | None = None
    #: the total flange friction power the design must stay under [W] (None: no limit): the
    #: upper 95 % bound of its time mean at most this at every operating point; the
    #: epsilon-constraint runs of the PV / friction-power front set it
    max_friction_power: float | None = None

    def __post_init__(self):
        """One-line errors naming the setting, before anything runs; a choice given by its name
        (text) is stored as its member."""
        for name, kind in (
            ("estimator", Estimator),
            ("corner_constraint", CornerConstraint),
            ("choose", Choice),
            ("statistic", Statistic),
        ):
            object.__setattr__(self, name, _member(kind, name, getattr(self, name)))
        for name in ("seeds", "verify_seeds"):
            require(name, getattr(self, name), lambda v: (v >= 1) & (v == np.round(v)), "an integer >= 1")
        require("skip_weight", self.skip_weight, lambda v: (v >= 0) & (v < 1), "in [0, 1)")
        require(
            "corner_risk_level",
            self.corner_risk_level,
            lambda v: (v > 0) & (v < 1),
            "in (0, 1) per revolution",
        )
        require(
            "recheck_every", self.recheck_every, lambda v: (v >= 1) & (v == np.round(v)), "an integer >= 1"
        )
        for name in ("window_revs", "verify_window_revs"):  # batch means need two batches
            require(name, getattr(self, name), lambda v: (v >= 2) & (v == np.round(v)), "an integer >= 2")
        require(
            "verify_first_seed",
            self.verify_first_seed,
            lambda v: (v >= 0) & (v == np.round(v)),
            "an integer >= 0",
        )
        if self.verify_first_seed < self.seeds:
            raise UserInputError(
                f"verify_first_seed = {self.verify_first_seed}: must be >= seeds = {self.seeds} "
                "(verification uses seeds the search never saw)"
            )
        if self.statistic is not Statistic.MEAN and self.estimator is not Estimator.FROZEN:
            raise UserInputError(
                f"statistic = {self.statistic.value!r} needs estimator = 'frozen' (not {self.estimator.value!r})"
            )
        require("gradient_window", self.gradient_window, lambda v: np.isfinite(v) & (v > 0), "> 0 s")
        require("corner_margin", self.corner_margin, lambda v: np.isfinite(v) & (v >= 0), ">= 0 m")
        require("rtol", self.rtol, lambda v: np.isfinite(v) & (v > 0) & (v < 1), "in (0, 1)")
        require("workers", self.workers, lambda v: (v >= 0) & (v == np.round(v)), "an integer >= 0")
        if self.min_film_parameter is not None:
            require("min_film_parameter", self.min_film_parameter, lambda v: np.isfinite(v) & (v > 0), "> 0")
        if self.max_flash_temperature is not None:
            require(
                "max_flash_temperature",
                self.max_flash_temperature,
                lambda v: np.isfinite(v) & (v > 0),
                "> 0 K",
            )
        if self.max_friction_power is not None:
            require(
                "max_friction_power", self.max_friction_power, lambda v: np.isfinite(v) & (v > 0), "> 0 W"
            )
        if self.clearance_step != "auto":
            if isinstance(self.clearance_step, str):
                raise UserInputError(
                    f"clearance_step = {self.clearance_step!r}: must be 'auto' or a number in [0, 1e-3) m"
                )
            require(
                "clearance_step",
                self.clearance_step,
                lambda v: np.isfinite(v) & (v >= 0) & (v < 1e-3),
                "'auto' or in [0, 1e-3) m",
            )

    @property
    def limits(self) -> tuple[tuple[str, float], ...]:
        """The limits set on what the faces are designed for besides PV, as (constraint name,
        value): "film_parameter" (`min_film_parameter`), "flash_temperature"
        (`max_flash_temperature`), "friction_power" (`max_friction_power`), in that order;
        empty without limits."""
        out = []
        if self.min_film_parameter is not None:
            out.append(("film_parameter", float(self.min_film_parameter)))
        if self.max_flash_temperature is not None:
            out.append(("flash_temperature", float(self.max_flash_temperature)))
        if self.max_friction_power is not None:
            out.append(("friction_power", float(self.max_friction_power)))
        return tuple(out)

    def measurement(self, *, verification: bool = False) -> run.SteadySettings:
        """The settled-run settings of one evaluation (or, with `verification`, of the
        verification): this object's seeds, window, settling, tolerance and workers as the one
        settings object of settled running (`jaxbearing.run.SteadySettings`), every other setting
        at its default there."""
        return run.SteadySettings(
            seeds=self.verify_seeds if verification else self.seeds,
            window_revs=self.verify_window_revs if verification else self.window_revs,
            settle=run.settling(self.settle),
            rtol=self.rtol,
            workers=self.num_workers,
        )

    @property
    def num_workers(self) -> int:
        """`workers`, or 0: one per CPU; on an accelerator one (the members are vmapped there,
        and worker processes would each claim the device)."""
        if int(self.workers):
            return int(self.workers)
        return available_cpus() if jax.default_backend() == "cpu" else 1
