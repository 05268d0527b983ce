"""Hunt-Crossley normal damping of Hertz-type contacts (Hunt & Crossley 1975).

Hunt & Crossley ("Coefficient of restitution interpreted as damping in vibroimpact", J. Appl.
Mech. 42:440-445, 1975) make the damping force proportional to the elastic one,

    Q = K delta^n (1 + c d(delta)/dt),        c = (3/2) alpha,

so it vanishes with the contact, never jumps when a contact opens or closes, and gives a
coefficient of restitution e = 1 - alpha v_in for small alpha v_in, whatever K, n and the mass.
The exact restitution of one impact follows in closed form: with v = d(delta)/dt,
m v dv / (1 + c v) = -K delta^n d(delta) integrates over the closed loop in delta to
f(v_in) = f(-v_out), f(v) = v/c - ln(1 + c v)/c^2, which expands to
e = v_out/v_in = 1 - (2/3) c v_in + (4/9) (c v_in)^2 + O((c v_in)^3).

This is the law the raceway and pocket slices use (`jaxbearing._raceway`, `jaxbearing._pocket`,
N = q s(1 + 1.5 alpha d(delta)/dt) with `HUNT_CROSSLEY_ALPHA` = 0.3 s/m): the same alpha
convention (Hunt and Crossley's, e = 1 - alpha v), the same factor and the same positivity
softplus s(x) = w softplus(x/w), w = `DAMPING_FACTOR_WIDTH` = 0.02. The softplus keeps the
factor positive (no adhesive pull when the bodies separate faster than 1/c = 2.2 m/s at the
default alpha) and differs from 1 + c v by w exp(-(1 + c v)/w), below 1e-21 near 1.

Hunt and Crossley's experimental alpha is 0.08 - 0.32 s/m for steel, bronze and ivory; the
default 0.3 s/m sits at the top because an oil film damps more than a dry contact.
"""

from __future__ import annotations

import jax
import jax.numpy as jnp
import numpy as np
from jaxtyping import Array, ArrayLike, Float

from ._smooth import PENETRATION_WIDTH, hertz_force

#: Hunt-Crossley alpha [s/m] (e = 1 - alpha v_in; Hunt & Crossley 1975: 0.08-0.32 s/m). Every steel
#: contact uses it (raceway slices, pocket, cage lands, roller end/flange).
HUNT_CROSSLEY_ALPHA = 0.3

#: Width of the softplus that keeps the factor 1 + 1.5 alpha d(delta)/dt positive (as in the
#: raceway and pocket contacts).
DAMPING_FACTOR_WIDTH = 0.02


def hunt_crossley_factor(
    interference_rate: Float[ArrayLike, "*#batch"],
    alpha: Float[ArrayLike, "*#batch"] = HUNT_CROSSLEY_ALPHA,
    width: Float[ArrayLike, "*#batch"] = DAMPING_FACTOR_WIDTH,
) -> Float[Array, "*batch"]:
    """Damping factor s(1 + (3/2) alpha d(delta)/dt), s(x) = w softplus(x/w) (Hunt & Crossley).

    Multiplies an elastic contact force. Equals 1 + 1.5 alpha d(delta)/dt to w exp(-x/w) (below
    1e-21 for x near 1), positive and C-infinity everywhere, tends to 0 (no pull) when the
    contact opens faster than 1/(1.5 alpha).

    Args:
        interference_rate: d(delta)/dt [m/s], positive while the bodies close in.
        alpha: Hunt-Crossley alpha [s/m] (restitution e = 1 - alpha v_in for small alpha v_in).
        width: softplus width w of the positivity guard (dimensionless).
    """
    x = 1.0 + 1.5 * jnp.asarray(alpha) * jnp.asarray(interference_rate)
    return width * jax.nn.softplus(x / width)


def hunt_crossley_force(
    stiffness: Float[ArrayLike, "*#batch"],
    interference: Float[ArrayLike, "*#batch"],
    interference_rate: Float[ArrayLike, "*#batch"],
    alpha: Float[ArrayLike, "*#batch"] = HUNT_CROSSLEY_ALPHA,
    exponent: float | Float[ArrayLike, "*#batch"] = 1.5,
    penetration_width: Float[ArrayLike, "*#batch"] = PENETRATION_WIDTH,
) -> Float[Array, "*batch"]:
    """Damped normal force Q = K delta_s^n s(1 + (3/2) alpha d(delta)/dt) [N] (Hunt & Crossley).

    delta_s = eps softplus(delta/eps) (`hertz_force`), s the positivity softplus of
    `hunt_crossley_factor`. Zero with zero derivatives far outside the contact, non-negative,
    C-infinity in (delta, d(delta)/dt) including delta = 0 and zero rate. For a point contact
    n = 3/2 and K from `point_contact_stiffness`.

    Args:
        stiffness: K [N/m^n].
        interference: delta [m] (positive = overlap).
        interference_rate: d(delta)/dt [m/s] (positive = closing), the normal approach speed of
            the material points at the contact.
        alpha: Hunt-Crossley alpha [s/m], default `HUNT_CROSSLEY_ALPHA`.
        exponent: n.
        penetration_width: eps [m] of the penetration softplus.
    """
    elastic = hertz_force(interference, stiffness, penetration_width, exponent)
    return elastic * hunt_crossley_factor(interference_rate, alpha)


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
