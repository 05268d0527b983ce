"""Friction power and flash temperature of the roller-end/flange contacts (docs/model.md 5.5).

Friction power. Per contact P_f = mu Q |u| [W]: the friction coefficient, the normal load and
the material sliding speed of `FlangeContact` (the power the friction force
F_t = -mu Q u / sqrt(|u|^2 + u_eps^2) dissipates is P_f |u| / sqrt(|u|^2 + u_eps^2), equal to
it but for the regularisation u_eps = 1 mm/s); per flange the sum over the rollers
(`flange_friction_power`), absent flanges 0 (their Q is 0, `without_absent_flanges`).

Flash temperature. The largest surface temperature rise of a uniform heat source of radius a
moving at speed V over a half-space of conductivity k and diffusivity kappa, for every Peclet
number Pe = V a / (2 kappa) (Tian & Kennedy 1994, "Maximum and average flash temperatures in
sliding contacts", ASME J. Tribology 116(1), 167-174: their interpolation for the uniform
circular source),

    theta_max = (q a / k) f(Pe),      f(Pe) = 2 / sqrt(pi (1.273 + Pe)),

with the two exact limits it joins (Carslaw & Jaeger, Conduction of Heat in Solids, 2nd ed.
1959): a stationary disc, theta = q a / k at its centre (f(0) = 2 / sqrt(1.273 pi) = 1.0001);
a fast source, the one-dimensional surface temperature 2 q sqrt(kappa t / pi) / k after the
time t = 2 a / V the centre line spends under it (Jaeger 1942), i.e. f -> 2 / sqrt(pi Pe).
Between them f lies within 2.3 % of a quadrature of the exact moving-source solution
(tests/test_flange_heat.py); the form and its constant are verified against these, the paper's
equation number is not quoted.

The contact: the Hertz ellipse (a, b) as the circle of equal area, radius a_e = sqrt(a b), with
the uniform flux q = P_f / (pi a_e^2) (a semi-ellipsoidal flux mu p(r) |u| of the same power has
a maximum 16-18 % higher at Pe = 0-100, by the same quadrature). The source moves over the roller
end at V_1 = |u_e + u/2| and over the rib at V_2 = |u_e - u/2| (the surfaces' velocities
relative to the contact point, from the entrainment velocity u_e and the sliding velocity u),
each body with its own Pe_i = V_i a_e / (2 kappa_i). Blok's postulate (1937) partitions the heat
so that both surfaces reach the same largest temperature: with theta_i = (q a_e / k_i) f(Pe_i)
the rise if body i took all the heat,

    Delta T = 1 / (1 / theta_1 + 1 / theta_2) = 2 P_f / (pi a_e sum_i k_i sqrt(pi (1.273 + Pe_i))).

The roller end is the roller's material, the rib the ring's (`Material.thermal_conductivity`,
`Material.thermal_diffusivity`). Delta T = 0 without load (P_f = 0 or a_e = 0).
"""

from __future__ import annotations

import jax.numpy as jnp
from jaxtyping import Array, ArrayLike, Float

from ..contact import safe_norm
from ..geometry import Bearing
from ._contact import FlangeContact

#: the constant of Tian & Kennedy's interpolation for the uniform circular source,
#: f(Pe) = 2 / sqrt(pi (TIAN_KENNEDY_CONSTANT + Pe)); 4 / pi to its 4 digits, so that f(0) = 1
TIAN_KENNEDY_CONSTANT = 1.273


def friction_power(contacts: FlangeContact) -> Float[Array, "*batch"]:
    """P_f = mu Q |u| of every contact [W] (module docstring)."""
    return contacts.friction_coefficient * contacts.normal_force * contacts.sliding_speed


def flange_friction_power(contacts: FlangeContact) -> Float[Array, "*lead 4"]:
    """The friction power of each flange [W], summed over the rollers: `contacts` with leading
    shape (..., Z, 4) (`all_flange_contacts`) -> (..., 4), in `FLANGE_ORDER`."""
    return jnp.sum(friction_power(contacts), axis=-2)


def flash_temperature_factor(peclet: ArrayLike) -> Float[Array, "*batch"]:
    """f(Pe) = 2 / sqrt(pi (1.273 + Pe)): the largest temperature rise of a uniform circular
    source in units of q a / k, Pe = V a / (2 kappa) (Tian & Kennedy 1994; module docstring)."""
    return 2.0 / jnp.sqrt(jnp.pi * (TIAN_KENNEDY_CONSTANT + jnp.asarray(peclet)))


def blok_flash_temperature(
    power: ArrayLike,
    radius: ArrayLike,
    speeds: tuple[ArrayLike, ArrayLike],
    conductivities: tuple[ArrayLike, ArrayLike],
    diffusivities: tuple[ArrayLike, ArrayLike],
) -> Float[Array, "*batch"]:
    """Largest flash temperature rise [K] of a uniform circular heat source of total power
    `power` [W] and radius `radius` [m] between two bodies over which it moves at `speeds`
    (V_1, V_2) [m/s], with conductivities (k_1, k_2) [W/(m K)] and diffusivities (kappa_1,
    kappa_2) [m^2/s], the heat shared by Blok's postulate of equal surface temperatures:

        Delta T = 2 P / (pi a sum_i k_i sqrt(pi (1.273 + Pe_i))),   Pe_i = V_i a / (2 kappa_i)

    (module docstring). 0 where the power or the radius is 0 (finite gradients there)."""
    p = jnp.asarray(power)
    a = jnp.asarray(radius)
    loaded = (a > 0) & (p > 0)
    a_safe = jnp.where(loaded, a, 1.0)
    resistance = sum(
        jnp.asarray(k)
        * jnp.sqrt(jnp.pi * (TIAN_KENNEDY_CONSTANT + jnp.abs(v) * a_safe / (2 * jnp.asarray(d))))
        for v, k, d in zip(speeds, conductivities, diffusivities)
    )
    return jnp.where(loaded, 2 * p / (jnp.pi * a_safe * resistance), 0.0)


def flange_heat_source_speeds(contacts: FlangeContact) -> tuple[Array, Array]:
    """(V_1, V_2): the speeds [m/s] of the roller end's and of the rib's surface relative to the
    contact point, |u_e + u/2| and |u_e - u/2| (module docstring)."""
    half = 0.5 * contacts.sliding_velocity
    ue = contacts.entrainment_velocity
    return safe_norm(ue + half), safe_norm(ue - half)


def flange_flash_temperature(bearing: Bearing, contacts: FlangeContact) -> Float[Array, "*batch"]:
    """Largest flash temperature rise [K] at every roller-end/rib contact of `contacts`: the
    friction power on the circle of the Hertz ellipse's area, radius sqrt(a b), moving over the
    roller end (roller material) and the rib (ring material), Blok's partition
    (`blok_flash_temperature`, module docstring)."""
    semi = contacts.ellipse_semi_axes
    radius = jnp.sqrt(jnp.maximum(semi[..., 0] * semi[..., 1], 0.0))
    roller, ring = bearing.roller_material, bearing.ring_material
    return blok_flash_temperature(
        friction_power(contacts),
        radius,
        flange_heat_source_speeds(contacts),
        (roller.thermal_conductivity, ring.thermal_conductivity),
        (roller.thermal_diffusivity, ring.thermal_diffusivity),
    )
