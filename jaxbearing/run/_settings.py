"""How a settled run starts, settles and measures: one typed, immutable settings object with
every default defined here, validated once (docs/model.md 16).

`SteadySettings` is what `simulate_steady`, `settle_members`, a settled sweep, the design metrics
and the gradient estimators take; the command line and the TOML files build it (`settling`
maps their text onto the settling objects). The settling mode is an object, as diffrax's step
controllers are:

* `SettleAuto()`: revolutions of the cage until the settling verdict finds the remaining drift of
  the cage speed below `SteadySettings.tolerance`, at most `SteadySettings.settle_cap_ms`;
* `SettleFixed(ms)`: a fixed settling time, declared settled by the user;
* `SettleOff()`: measure from the start (nothing verified: the statistics are a start-up
  transient's).
"""

from __future__ import annotations

import dataclasses

import numpy as np

from .._errors import UserInputError
from ..dynamics import Functionals, Params
from ..io import require
from ._engine import STRATEGIES
from ._initial import STARTS
from ._rosenbrock import DEFAULT_SOLVER, check_solver

#: the settling verdict's tolerance: the largest remaining relative drift of the revolution-mean
#: cage speed that counts as settled
SETTLE_TOLERANCE = 1e-3
#: the longest settling time [ms] before the run is measured as not settled
SETTLE_CAP_MS = 300.0
#: samples saved per cage revolution: 5 us at the reference cage speed, as `simulate`'s default
#: 4000 per 20 ms
SAVES_PER_REV = 1320


@dataclasses.dataclass(frozen=True)
class SettleAuto:
    """Settle until the settling verdict passes (`settling_verdict`; docs/model.md 16)."""

    value = "auto"  # as the command line and the TOML files write it
    mode = "auto"  # as the summary names it

    def __str__(self) -> str:
        return "auto"


@dataclasses.dataclass(frozen=True)
class SettleFixed:
    """Settle for a fixed time `ms` [ms] (>= 0), declared settled by the user."""

    ms: float
    mode = "fixed"

    def __post_init__(self):
        value = _as_float("settle", self.ms)
        require(
            "settle", value, lambda v: np.isfinite(v) & (v >= 0), '"auto", "off" or a settling time >= 0 ms'
        )
        object.__setattr__(self, "ms", value)

    @property
    def value(self) -> float:
        """The settling time [ms], as the command line and the TOML files write it."""
        return self.ms

    def __str__(self) -> str:
        return f"{self.ms:g} ms"


@dataclasses.dataclass(frozen=True)
class SettleOff:
    """No settling: the window starts at the start (its statistics are a start-up transient's)."""

    value = "off"
    mode = "off"

    def __str__(self) -> str:
        return "off"


Settling = SettleAuto | SettleFixed | SettleOff


def _as_float(name: str, value) -> float:
    try:
        return float(value)
    except (TypeError, ValueError):
        raise UserInputError(
            f'{name} = {value!r}: must be "auto", "off" or a settling time >= 0 ms'
        ) from None


def settling(value) -> Settling:
    """The settling object of `value`: a settling object itself, or the text of the command line
    and the TOML files ("auto", "off", or a settling time in ms, as a number or its text). The
    one place where that text becomes an object; a bad value gets one line naming `settle`
    (`SettleFixed` checks the time)."""
    if isinstance(value, SettleAuto | SettleFixed | SettleOff):
        return value
    if isinstance(value, str) and value in ("auto", "off"):
        return SettleAuto() if value == "auto" else SettleOff()
    if isinstance(value, bool):
        raise UserInputError(f'settle = {value!r}: must be "auto", "off" or a settling time >= 0 ms')
    return SettleFixed(value)


@dataclasses.dataclass(frozen=True)
class SteadySettings:
    """How every member of a settled run starts, settles and measures. Every default of settled
    running is defined here once; `simulate_steady`, `settle_members`, sweeps, the design
    metrics, the gradient estimators and the design search take this object (the search's own
    choices, e.g. shorter windows while searching, are its settings' fields built on it).

    settle: `SettleAuto()` (default), `SettleFixed(ms)` or `SettleOff()` (`settling` maps
        "auto", "off" and a number of ms onto them).
    window_revs: measurement window [cage revolutions], >= 2 (batch means need two batches).
    seeds: independent seeded initial scatters per case, `Perturbation.seed` first_seed ..
        first_seed + seeds - 1.
    tolerance: the settling verdict's largest remaining relative drift of the cage speed.
    settle_cap_ms: the longest settling time [ms].
    start: "skid" (the skid equilibrium and its pre-start) or "quasi-static" (kinematic speeds).
    rtol, atol: the integrator's tolerances (`solve`'s error norm of settled windows).
    max_steps: step limit of one integration request.
    saves_per_rev: samples saved per cage revolution in the window.
    functionals: the smooth flange functionals integrated in the state.
    solver: "tsit5" (default) or "ros34pw2".
    strategy: the engine's driver (`STRATEGIES`: "auto", "sequential", "processes", "vmap").
    workers: processes for the "processes" strategy (>= 1).
    progress: print the settling of each member.
    continuation_settle_revs: members continuing from a given state settle this many of their own
        cage revolutions instead of by `settle` (None: by `settle`).
    """

    settle: Settling = SettleAuto()
    window_revs: int = 8
    seeds: int = 1
    tolerance: float = SETTLE_TOLERANCE
    settle_cap_ms: float = SETTLE_CAP_MS
    start: str = "skid"
    rtol: float = 1e-3
    atol: float = 1e-6
    max_steps: int = 2_000_000
    saves_per_rev: int = SAVES_PER_REV
    functionals: Functionals = Functionals()
    solver: str = DEFAULT_SOLVER
    strategy: str = "auto"
    workers: int = 1
    progress: bool = False
    continuation_settle_revs: int | None = None

    def __post_init__(self):
        """Every check of a settled run's settings, before anything runs: one line naming the
        setting, its value and the valid range."""
        set_ = object.__setattr__
        set_(self, "settle", settling(self.settle))
        integer = lambda v: v == np.round(v)  # noqa: E731
        require(
            "window_revs",
            self.window_revs,
            lambda v: (v >= 2) & integer(v),
            "an integer >= 2 (cage revolutions; batch means need two batches)",
        )
        require("seeds", self.seeds, lambda v: (v >= 1) & integer(v), "an integer >= 1")
        require(
            "settle_tolerance", self.tolerance, lambda v: (v > 0) & (v < 1), "in (0, 1) (relative change)"
        )
        require("settle_cap_ms", self.settle_cap_ms, lambda v: np.isfinite(v) & (v > 0), "> 0 ms")
        if self.start not in STARTS:
            raise UserInputError(f"start = {self.start!r}: must be one of {', '.join(map(repr, STARTS))}")
        require("rtol", self.rtol, lambda v: np.isfinite(v) & (v > 0) & (v < 1), "in (0, 1)")
        require("atol", self.atol, lambda v: np.isfinite(v) & (v > 0) & (v < 1), "in (0, 1)")
        require("max_steps", self.max_steps, lambda v: (v >= 1) & integer(v), "an integer >= 1")
        require("saves_per_rev", self.saves_per_rev, lambda v: (v >= 1) & integer(v), "an integer >= 1")
        check_solver(self.solver)
        if self.strategy not in STRATEGIES:
            raise UserInputError(
                f"strategy = {self.strategy!r}: must be one of {', '.join(map(repr, STRATEGIES))}"
            )
        require("workers", self.workers, lambda v: (v >= 1) & integer(v), "an integer >= 1")
        if self.continuation_settle_revs is not None:
            require(
                "continuation_settle_revs",
                self.continuation_settle_revs,
                lambda v: (v >= 0) & integer(v),
                "an integer >= 0 (revolutions), or None",
            )
            set_(self, "continuation_settle_revs", int(self.continuation_settle_revs))
        for name in ("window_revs", "seeds", "max_steps", "saves_per_rev", "workers"):
            set_(self, name, int(getattr(self, name)))
        for name in ("tolerance", "settle_cap_ms"):
            set_(self, name, float(getattr(self, name)))

    def replace(self, **changes) -> SteadySettings:
        """A copy with `changes` (checked as a new object); a name that is not a setting gets one
        line listing the settings."""
        unknown = sorted(set(changes) - {f.name for f in dataclasses.fields(self)})
        if unknown:
            raise UserInputError(
                f"{unknown[0]}: not a setting of settled running; the settings are "
                + ", ".join(f.name for f in dataclasses.fields(self))
            )
        return dataclasses.replace(self, **changes)

    def record(self) -> dict:
        """The settings as summary.json records them (the settling mode as the command line writes
        it; the smooth functionals and the progress flag left out)."""
        skip = ("functionals", "progress")
        out = {f.name: getattr(self, f.name) for f in dataclasses.fields(self) if f.name not in skip}
        out["settle"] = self.settle.value
        return out

    def tolerances(self, member) -> tuple[float, float]:
        """(rtol, atol) of `member` (`Member`): its own where given, else these."""
        return (
            float(self.rtol if member.rtol is None else member.rtol),
            float(self.atol if member.atol is None else member.atol),
        )

    def params(self, member) -> Params:
        """The model parameters of `member`'s run."""
        return Params(bearing=member.bearing, operating=member.operating, functionals=self.functionals)


def steady_settings(
    names: dict | None = None, base: SteadySettings | None = None, **values
) -> SteadySettings:
    """`base` (default `SteadySettings()`) with `values`, for the command line and the TOML
    readers: a bad value's one-line error names the option as the user wrote it, `names` mapping
    the settings' names (e.g. {"window_revs": "--window-revs", "settle_tolerance":
    "--settle-tolerance"}) onto the user's."""
    try:
        return (base if base is not None else SteadySettings()).replace(**values)
    except UserInputError as exc:
        text = str(exc)
        for name, shown in (names or {}).items():
            if text.startswith((f"{name} = ", f"{name}: ")):
                raise UserInputError(shown + text[len(name) :]) from None
        raise
