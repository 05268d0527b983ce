"""Hunt-Crossley normal damping: the dissipative factor shared by every contact.

Hunt & Crossley (1975), "Coefficient of restitution interpreted as damping in vibroimpact",
J. Appl. Mech. 42:440-445: the normal force of a Hertzian contact is

    Q = K delta^n (1 + lambda d(delta)/dt),   lambda = 1.5 alpha,

with alpha [s/m] the slope of the coefficient of restitution against impact speed for small
speeds, e ~ 1 - alpha v_in (steel on steel: alpha = 0.08-0.32 s/m). The force vanishes with the
interference (no jump at first contact or separation, unlike Kelvin-Voigt damping).

The factor is s(1 + lambda d(delta)/dt) with s a softplus of width 0.02: equal to the factor to
within 1e-9 once it exceeds 0.4, and positive for fast separation (no adhesive pull).

Exact restitution of one impact (1-DOF, mass m, no other force): from m v dv / (1 + lambda v) =
-K delta^n d(delta), the rebound speed v_out satisfies f(v_in) = f(-v_out) with
f(v) = v / lambda - ln(1 + lambda v) / lambda^2 (independent of K, n and m);
`restitution_coefficient` solves it (tests/test_contact_damping.py integrates the impact).
"""

from __future__ import annotations

import jax
import jax.numpy as jnp
import numpy as np
from jaxtyping import Array, ArrayLike, Float

#: Hunt-Crossley alpha [s/m] of every steel contact (Hunt & Crossley 1975: 0.08-0.32 s/m).
HUNT_CROSSLEY_ALPHA = 0.3
#: width of the softplus that keeps the factor 1 + 1.5 alpha d(delta)/dt positive.
DAMPING_FACTOR_WIDTH = 0.02


def hunt_crossley_factor(
    approach_rate: Float[ArrayLike, "*batch"], alpha: ArrayLike = HUNT_CROSSLEY_ALPHA
) -> Float[Array, "*batch"]:
    """s(1 + 1.5 alpha d(delta)/dt): multiply the elastic load by it. `approach_rate` is
    d(delta)/dt [m/s], positive while the bodies close in."""
    x = 1.0 + 1.5 * alpha * jnp.asarray(approach_rate)
    return DAMPING_FACTOR_WIDTH * jax.nn.softplus(x / DAMPING_FACTOR_WIDTH)


def restitution_coefficient(impact_speed: float, alpha: float = HUNT_CROSSLEY_ALPHA) -> float:
    """e = v_out / v_in of one Hunt-Crossley impact at `impact_speed` [m/s] (exact; module
    docstring), by bisection on f(-v_out) = f(v_in). NumPy, for tests and reports."""
    lam = 1.5 * alpha
    if lam * impact_speed < 1e-8:
        return 1.0

    def f(v):
        return v / lam - np.log1p(lam * v) / lam**2

    target = f(impact_speed)
    lo, hi = 0.0, min(impact_speed, (1.0 - 1e-15) / lam)
    for _ in range(200):
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if f(-mid) < target else (lo, mid)
    return 0.5 * (lo + hi) / impact_speed
