"""Whole-bearing dynamics: state layout, rigid-body rates, the vector field, the quasi-static start.

- state (docs/model.md 2): `State` of `RollerState` (Z rollers), `CageState`, `RingState` and the
  integrated `Accumulators`; `state_scales` / `Scaling` for the scaled integration state;
- rigid bodies: `axisymmetric_body_rates` (Euler's equations with gyroscopic terms, no small
  angles), `angular_momentum`, `kinetic_energy`;
- the vector field: `physical_rates(t, state, params)` over every roller, the cage and the inner
  ring, with `contact_loads` (every contact of one state) and the smooth `Functionals`;
- the start (docs/model.md 12): `quasi_static` (load distribution with centrifugal force) and
  `skid_equilibrium` (the speeds of steady running at those positions) with the
  `cage_time_constant` of the cage speed's slow approach to it; `skid_balance` (the terms of
  its roller and cage balances, resolved by contact), `skid_zones` (summed by zone) and
  `balanced_cage_torque` (the cage torque with the rollers in balance, at any cage speed).

May import: `jaxbearing._errors`, `contact`, `geometry`, `io`, `flange`, `forces`.
"""

from ._field import (
    FLANGE_NAMES,
    Functionals,
    Loads,
    Params,
    RingPose,
    contact_loads,
    inner_ring_pose,
    physical_rates,
)
from ._quasistatic import QuasiStatic, quasi_static
from ._rigid_body import angular_momentum, axisymmetric_body_rates, kinetic_energy
from ._skid import (
    SkidBalance,
    SkidEquilibrium,
    SkidZones,
    balanced_cage_torque,
    cage_time_constant,
    skid_balance,
    skid_equilibrium,
    skid_zones,
)
from ._state import (
    SCALED_UNITS,
    Accumulators,
    CageState,
    RingState,
    RollerState,
    Scaling,
    State,
    radial_unit,
    state_scales,
    tangential_unit,
)

__all__ = [
    "FLANGE_NAMES",
    "SCALED_UNITS",
    "Accumulators",
    "CageState",
    "Functionals",
    "Loads",
    "Params",
    "QuasiStatic",
    "RingPose",
    "RingState",
    "RollerState",
    "Scaling",
    "SkidBalance",
    "SkidEquilibrium",
    "SkidZones",
    "State",
    "angular_momentum",
    "axisymmetric_body_rates",
    "balanced_cage_torque",
    "cage_time_constant",
    "contact_loads",
    "inner_ring_pose",
    "kinetic_energy",
    "physical_rates",
    "quasi_static",
    "radial_unit",
    "skid_balance",
    "skid_equilibrium",
    "skid_zones",
    "state_scales",
    "tangential_unit",
]
