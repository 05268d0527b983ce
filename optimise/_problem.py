"""The design problem: bounds, operating envelope, scaled objective and constraints.

Variables. The design x = (R_end [m], theta_f [rad], Delta_bf [m]) (`Bounds`), or the eight
profile variables (`ProfileBounds`: the shapes of the roller end and the rib face, docs/model.md
5.4), is searched in the unit box: x = lo + u (hi - lo), u in [0, 1]^n, so every variable is
O(1) and the box bounds are a projection (a clip). A variable whose bounds coincide (lo = hi)
is held fixed.

Objective. The smooth peak flange PV of the dynamic run (`jaxbearing.design_metrics`: a p-norm
over contact time of p_max |u|, integrated inside the diffrax solve) in GPa m/s, at every
operating point of the envelope, evaluated in one vmapped batch, and combined either as a
weighted mean, or as the worst case through a smooth maximum (weighted log-sum-exp with
temperature T: J = T log sum_k w_k exp(PV_k / T), w_k normalised; J -> max_k PV_k as T -> 0).

Horizon (a limitation, measured). The dynamic objective is evaluated over a short horizon
(`DEFAULT_DURATION`, 0.3 ms from the seated start), because gradients through longer runs pass
through roller-flange impacts and stop being reliable (`jaxbearing.design.design_metrics`: central
differences no longer converge). Over so short a horizon the peak PV measures how hard the
seated rollers are driven onto their flanges in the first 0.3 ms: about 2 GPa m/s at the
reference design (R_end 80 mm, theta_f 1.6 deg), but almost zero (1e-7 GPa m/s) for designs such
as R_end 100-120 mm, theta_f 1.3-1.7 deg at Delta_bf 0.2 mm, whose rollers are not yet loaded
against the flange within the horizon. The search finds those designs; whether they keep a low
PV in steady running needs longer runs (`jaxbearing simulate`) to confirm. Pass `duration`
(`--duration-ms`) for longer horizons.

Constraints. The four margins of the design zone (`jaxbearing.design_zone`, the paper's
Figure 14): contact ellipse above the flange relief, contact height below the upper limit,
contact inside the limited circle, actual axial clearance Lambda_bf above `min_clearance`.
They are static and cheap (no dynamics), scaled by `MARGIN_SCALE` (0.1 mm) to O(1), and
tightened by `tighten` (scaled units) so that the small constraint violation an augmented
Lagrangian leaves at its limit point still satisfies the true constraint.
"""

from __future__ import annotations

import math
from collections.abc import Sequence

import equinox as eqx
import jax
import jax.numpy as jnp
import numpy as np
from jaxtyping import Array, Float

from jaxbearing import Bearing, OperatingPoint, Perturbation, UserInputError, rad_s_to_rpm, rpm_to_rad_s
from jaxbearing.design import design_metrics, seated_perturbation
from jaxbearing.flange import (
    DEFAULT_FLANGE_LOAD,
    DesignVariables,
    ProfileVariables,
    design_zone_grid,
    zone_margins,
)
from jaxbearing.io import check_model_inputs, check_solver_arguments, require

from ._bounds import MM, Bounds, ProfileBounds, box_from_engineering

#: scale of the design-zone margins (constraints are margin / MARGIN_SCALE)
MARGIN_SCALE = 0.1 * MM
#: scale of the objective (PV in GPa m/s)
PV_SCALE = 1e9
#: default simulated time per evaluation [s] and initial roller skew scatter [rad]. The rollers
#: start from `seated_perturbation` (the outermost roller at zero interference with its flange,
#: every design from an equivalent state) with a skew scatter of +/- 1 mrad (0.06 deg, the order
#: of roller skew in high-speed bearings); skew drives them onto the flanges at once, and within
#: 0.3 ms at 20,000 rpm the smooth peak PV reaches about 2 GPa m/s on the reference bearing, the
#: order of the paper's arc-end PV (below 3 GPa m/s). With the default scatter (1e-4 rad) the
#: first contacts are gentle and the PV stays four orders of magnitude lower over 0.5 ms.
DEFAULT_DURATION = 0.3e-3
DEFAULT_SKEW = 1e-3


def bounds_from_engineering(
    end_radius_mm: Sequence[float] | None = None,
    layback_angle_deg: Sequence[float] | None = None,
    axial_clearance_mm: Sequence[float] | None = None,
    base: Bounds | None = None,
) -> Bounds:
    """Bounds from engineering units (None keeps `base`, default `Bounds()`)."""
    values = dict(
        end_radius_mm=end_radius_mm,
        layback_angle_deg=layback_angle_deg,
        axial_clearance_mm=axial_clearance_mm,
    )
    return box_from_engineering(Bounds, values, base)


def operating_envelope(
    base: OperatingPoint,
    speeds_rpm: Sequence[float] | None = None,
    loads_N: Sequence[float] | None = None,
) -> OperatingPoint:
    """Stacked operating points (leading axis) for every (speed, load) pair of the cartesian
    product; None keeps the base value. Gravity, misalignment, axial load and the ring
    freedoms are those of `base`."""
    speeds = [float(base.inner_speed)] if not speeds_rpm else [rpm_to_rad_s(float(s)) for s in speeds_rpm]
    loads = [float(base.radial_load)] if not loads_N else [float(f) for f in loads_N]
    for s in speeds:
        if not (math.isfinite(s) and s > 0):
            raise UserInputError(f"speeds_rpm: {s * 60 / (2 * math.pi):g}: must be > 0 rpm")
    for f in loads:
        if not (math.isfinite(f) and f > 0):
            raise UserInputError(f"loads_N: {f:g}: must be > 0 N")
    sp, ld = np.meshgrid(speeds, loads, indexing="ij")
    n = sp.size
    return OperatingPoint(
        inner_speed=sp.ravel(),
        radial_load=ld.ravel(),
        gravity=np.full(n, float(base.gravity)),
        misalignment=np.full(n, float(base.misalignment)),
        axial_load=np.full(n, float(base.axial_load)),
        axial_freedom=np.full(n, float(base.axial_freedom)),
        tilt_freedom=np.full(n, float(base.tilt_freedom)),
    )


class DesignProblem(eqx.Module):
    """Minimise the (robust) smooth peak flange PV over the box `bounds` subject to the design
    zone. `operating` holds K stacked operating points; `weights` (K,) their weights.

    `aggregate`: "max" (smooth worst case, log-sum-exp with `temperature` in the objective's
    unit: GPa m/s, or W for the steady search's friction statistic) or
    "mean" (weighted mean). `tighten`: constraint back-off in scaled units (x 0.1 mm)."""

    bearing: Bearing
    operating: OperatingPoint
    weights: Float[Array, " K"]
    #: the search box: `Bounds` (R_end, theta_f, Delta_bf) or `ProfileBounds` (the eight
    #: profile variables); its kind decides the kind of design searched
    bounds: Bounds | ProfileBounds = eqx.field(static=True)
    duration: float = eqx.field(static=True, default=DEFAULT_DURATION)
    flange_load: float = eqx.field(static=True, default=DEFAULT_FLANGE_LOAD)
    min_clearance: float = eqx.field(static=True, default=0.0)
    aggregate: str = eqx.field(static=True, default="max")
    temperature: float = eqx.field(static=True, default=0.1)
    tighten: float = eqx.field(static=True, default=0.01)
    rtol: float = eqx.field(static=True, default=1e-3)
    atol: float = eqx.field(static=True, default=1e-6)
    max_steps: int = eqx.field(static=True, default=200_000)
    #: initial roller scatter: "seated" (`jaxbearing.seated_perturbation` with skew scatter
    #: `initial_skew`: axial scatter scaled to each design's play), or a Perturbation, or None
    perturbation: Perturbation | str | None = eqx.field(static=True, default="seated")
    initial_skew: float = eqx.field(static=True, default=DEFAULT_SKEW)
    #: per operating point, the bearing it runs with (stacked, leading axis K): the corners of
    #: the model's uncertain constants as further operating points (`make_problem`'s
    #: `constant_corners`); None: every point runs `bearing`
    point_bearings: Bearing | None = None
    #: per operating point, the name of its corner of the constants ("nominal",
    #: "traction_d-, oil_fraction+"); None without corners
    point_constants: tuple[str, ...] | None = eqx.field(static=True, default=None)

    def __check_init__(self):
        """Every setting before anything is traced: the solver arguments
        (`jaxbearing.io.check_solver_arguments`), the bounds against this bearing's roller, the
        bearing and the operating points (`check_model_inputs`), and the search's own options."""
        if self.aggregate not in ("max", "mean"):
            raise UserInputError(f"aggregate = {self.aggregate!r}: must be 'max' or 'mean'")
        require(
            "temperature",
            self.temperature,
            lambda v: np.isfinite(v) & (v > 0),
            "> 0 and finite (the objective's unit)",
        )
        check_solver_arguments(
            duration=self.duration, rtol=self.rtol, atol=self.atol, max_steps=self.max_steps
        )
        if (
            self.perturbation is not None
            and isinstance(self.perturbation, str)
            and self.perturbation != "seated"
        ):
            raise UserInputError(
                f"perturbation = {self.perturbation!r}: must be 'seated', a Perturbation or None"
            )
        require("flange_load", self.flange_load, lambda v: np.isfinite(v) & (v > 0), "> 0 N and finite")
        require("min_clearance", self.min_clearance, np.isfinite, "finite (m)")
        require("initial_skew", self.initial_skew, lambda v: np.isfinite(v) & (v >= 0), ">= 0 rad and finite")
        require("tighten", self.tighten, lambda v: np.isfinite(v) & (v >= 0), ">= 0 and finite")
        self.bounds.check(self.bearing)
        check_model_inputs(self.bearing, self.operating)

    @property
    def num_operating_points(self) -> int:
        return int(np.shape(self.operating.inner_speed)[0])

    def point_label(self, k: int) -> str:
        """Operating point k in words: "10000 rpm, 1000 N", with its corner of the constants."""
        rpm = float(rad_s_to_rpm(np.asarray(self.operating.inner_speed)[k]))
        text = f"{rpm:.0f} rpm, {float(np.asarray(self.operating.radial_load)[k]):.0f} N"
        return text if self.point_constants is None else f"{text}, {self.point_constants[k]}"

    def bearing_at(self, k: int) -> Bearing:
        """The bearing operating point k runs with (`point_bearings`, else `bearing`)."""
        if self.point_bearings is None:
            return self.bearing
        return jax.tree_util.tree_map(lambda a: a[k], self.point_bearings)

    @property
    def num_variables(self) -> int:
        """n, the length of the design arrays (3, or 8 for a profile)."""
        return len(self.bounds.names)

    def design(self, u) -> DesignVariables | ProfileVariables:
        """The design at the scaled point u (`Bounds.variables`)."""
        return self.bounds.variables(self.bounds.from_scaled(u))

    # -- objective (expensive: one dynamic solve per operating point) --------------------
    def peak_pv(self, u: Float[Array, " n"]) -> Float[Array, " K"]:
        """Smooth peak PV [GPa m/s] at every operating point (one vmapped batch)."""
        import diffrax

        if self.point_bearings is not None:
            raise UserInputError(
                "uncertain constants: the start-up objective runs one bearing; use the steady objective"
            )
        if self.num_variables != 3:
            raise UserInputError(
                "profile bounds: the start-up objective searches R_end, theta_f, Delta_bf; use the steady objective"
            )

        design = self.design(u)
        if isinstance(self.perturbation, str):
            perturbation = seated_perturbation(design.apply(self.bearing), skew=self.initial_skew)
        else:
            perturbation = self.perturbation

        def one(op):
            m = design_metrics(
                self.bearing,
                op,
                design,
                duration=self.duration,
                flange_load=self.flange_load,
                min_clearance=self.min_clearance,
                rtol=self.rtol,
                atol=self.atol,
                max_steps=self.max_steps,
                adjoint=diffrax.ForwardMode(),
                perturbation=perturbation,
            )
            return m.peak_pv / PV_SCALE

        return jax.vmap(one)(self.operating)

    def combine(self, pv: Float[Array, " K"]) -> Float[Array, ""]:
        """Weighted mean, or smooth max T log sum_k w_k exp(PV_k / T), of per-point PV."""
        w = self.weights / jnp.sum(self.weights)
        if self.aggregate == "mean":
            return jnp.sum(w * pv)
        t = self.temperature
        m = jax.lax.stop_gradient(jnp.max(pv))
        return m + t * jnp.log(jnp.sum(w * jnp.exp((pv - m) / t)))

    def objective(self, u: Float[Array, " n"]) -> Float[Array, ""]:
        """Robust smooth peak PV [GPa m/s] of the scaled design u."""
        return self.combine(self.peak_pv(u))

    # -- constraints (cheap, static) -------------------------------------------------------
    def margins(self, u: Float[Array, " n"]) -> Float[Array, 4]:
        """Design-zone margins [m] (relief, height, limited circle, clearance), as one compiled
        program per problem structure (`_zone_margins`)."""
        return _zone_margins(self, u)

    def constraints(self, u: Float[Array, " n"]) -> Float[Array, 4]:
        """Scaled, tightened constraints c(u) = margins / MARGIN_SCALE - tighten >= 0."""
        return self.margins(u) / MARGIN_SCALE - self.tighten


def make_problem(
    bearing: Bearing,
    base_op: OperatingPoint,
    *,
    bounds: Bounds | None = None,
    speeds_rpm: Sequence[float] | None = None,
    loads_N: Sequence[float] | None = None,
    weights: Sequence[float] | None = None,
    constant_corners: Sequence[tuple[str, Bearing]] | None = None,
    **kwargs,
) -> DesignProblem:
    """A DesignProblem over the (speed x load) envelope around `base_op`. `constant_corners`:
    (name, bearing) pairs, the bearing with the model's uncertain constants at one corner of
    their ranges (`jaxbearing.design.robustness_corners`): every envelope point runs at every
    corner, as a further operating point of the same weight, so that the smooth maximum takes
    the worst corner too (docs/model.md 17)."""
    ops = operating_envelope(base_op, speeds_rpm, loads_N)
    k = int(np.shape(ops.inner_speed)[0])
    if weights is None:
        w = np.ones(k)
    else:
        w = np.asarray([float(v) for v in weights])
        if w.shape != (k,):
            raise UserInputError(
                f"weights: {len(w)} given, expected one per operating point ({k} = speeds x loads)"
            )
        if not np.all(np.isfinite(w) & (w >= 0)) or w.sum() <= 0:
            raise UserInputError(f"weights = {w.tolist()}: must be >= 0 with a positive sum")
    if constant_corners:
        names = tuple(name for name, _ in constant_corners for _ in range(k))
        each = [b for _, b in constant_corners for _ in range(k)]
        kwargs |= dict(
            point_bearings=jax.tree_util.tree_map(lambda *a: jnp.stack(a), *each),
            point_constants=names,
        )
        ops = jax.tree_util.tree_map(lambda a: jnp.concatenate([a] * len(constant_corners)), ops)
        w = np.tile(w, len(constant_corners))
    return DesignProblem(
        bearing=bearing, operating=ops, weights=jnp.asarray(w), bounds=bounds or Bounds(), **kwargs
    )


def feasibility_map(problem: DesignProblem, axial_clearance: float, n: int = 81):
    """Design-zone margins over an n x n grid of (R_end, theta_f) within the bounds at fixed
    Delta_bf (`jaxbearing.design_zone_grid`, one vmap). Returns (R_end [m], theta_f [rad],
    DesignZone) with fields of shape (n, n), axis 0 = R_end."""
    if problem.num_variables != 3:
        raise UserInputError("feasibility_map: a map of (R_end, theta_f) needs the three-variable bounds")
    lo, hi = problem.bounds.lower, problem.bounds.upper
    r = np.linspace(lo[0], hi[0], n)
    t = np.linspace(lo[1], hi[1], n)
    z = design_zone_grid(
        problem.bearing,
        r[:, None],
        t[None, :],
        axial_clearance,
        problem.flange_load,
        problem.min_clearance,
    )
    return r, t, z


@eqx.filter_jit
def _zone_margins(problem: DesignProblem, u: Float[Array, " n"]) -> Float[Array, 4]:
    """`DesignProblem.margins` compiled: called eagerly, the loops inside `zone_margins` compiled
    a program of their own at every call (0.2 s each; 40 calls in one command-line test of the
    search), and inside a traced function the jit is inlined."""
    return zone_margins(
        problem.bearing,
        problem.design(u),
        flange_load=problem.flange_load,
        min_clearance=problem.min_clearance,
    )


@eqx.filter_jit
def margins_batch(problem: DesignProblem, u: Float[Array, "N n"]) -> Float[Array, "N 4"]:
    """Design-zone margins [m] of a batch of scaled designs (one compiled vmap)."""
    return jax.vmap(problem.margins)(u)


def any_feasible(problem: DesignProblem, n: int = 41) -> tuple[bool, np.ndarray | None]:
    """Whether some design on a grid over the bounds satisfies every (tightened) margin;
    returns (found, the point with the largest minimum margin, scaled u). Three variables: the
    n^3 grid; more: n^3 points of a Halton sequence over the free variables (a grid of eight
    variables would be n^8)."""
    free = (problem.bounds.upper - problem.bounds.lower) > 0
    if problem.num_variables == 3:
        axes = [np.linspace(0.0, 1.0, n if f else 1) for f in free]
        uu = np.stack(np.meshgrid(*axes, indexing="ij"), axis=-1).reshape(-1, 3)
    else:
        uu = np.where(free, halton_points(n**3, problem.num_variables), 0.0)
    c = np.asarray(margins_batch(problem, jnp.asarray(uu))) / MARGIN_SCALE - problem.tighten
    worst = c.min(axis=1)
    i = int(np.argmax(worst))
    return bool(worst[i] > 0), uu[i]


#: the first primes: the bases of the Halton sequence, one per variable
PRIMES = (2, 3, 5, 7, 11, 13, 17, 19, 23, 29, 31, 37)


def halton(i: int, base: int) -> float:
    """The i-th element (i >= 1) of the van der Corput sequence in `base`."""
    f, r = 1.0, 0.0
    while i > 0:
        f /= base
        r += f * (i % base)
        i //= base
    return r


def halton_points(count: int, dimension: int, first: int = 1) -> np.ndarray:
    """`count` points (count, dimension) of the Halton sequence in [0, 1]^dimension, from
    element `first`; bases the first primes."""
    if dimension > len(PRIMES):
        raise ValueError(f"dimension = {dimension}: at most {len(PRIMES)}")
    rows = [[halton(i, b) for b in PRIMES[:dimension]] for i in range(first, first + count)]
    return np.array(rows, dtype=float).reshape(count, dimension)
