"""Lubricated point contact: EHL film thickness, film parameter, mixed-lubrication traction.

Viscosity at temperature (exponential, Reynolds' law; the form behind the source paper's
temperature-viscosity coefficient, Machines 2025 sec. 4: eta_0 = 0.055 Pa s at the 80 C oil
supply, beta_T = 0.0315 1/C, alpha_p = 1.85e-8 1/Pa):

    eta(T) = eta_0 exp(-beta_T (T - T_0)).

Film thickness (Hamrock & Dowson, "Isothermal elastohydrodynamic lubrication of point contacts,
Part III: fully flooded results", J. Lubr. Technol. 99:264-276, 1977, for h_min; the central
film as given with it in Hamrock & Dowson, Ball Bearing Lubrication, Wiley 1981, and Hamrock,
Schmid & Jacobson, Fundamentals of Fluid Film Lubrication, 2nd ed. 2004), for rolling
(entrainment) along x:

    H_min = h_min / R_x = 3.63 U^0.68 G^0.49 W^-0.073 (1 - exp(-0.68 k))
    H_c   = h_c / R_x   = 2.69 U^0.67 G^0.53 W^-0.067 (1 - 0.61 exp(-0.73 k))
    U = eta_0 u_e / (E' R_x),   G = alpha_p E',   W = Q / (E' R_x^2),   k = a_y / a_x

with the mean entrainment speed u_e = |u_1 + u_2| / 2 (surface velocities relative to the
contact), E' in Hamrock's convention (`effective_modulus`), R_x the effective radius along the
entrainment direction, R_y across it, and k the ellipticity of the Hertz ellipse (transverse over
rolling-direction semi-axis), here the EXACT one (`point_contact_ellipticity`) rather than
Hamrock & Dowson's fit k = 1.03 (R_y/R_x)^0.64, which they used with the formulas (the fit is 3 %
high at k = 1, within 1.8 % for 1.5 <= k <= 8; that moves the factor (1 - exp(-0.68 k)) by 2.1 %
at k = 1 and by less than 0.9 % for k >= 1.5).

Validity: isothermal, fully flooded, Newtonian, smooth surfaces; Hamrock & Dowson fitted 34
computed cases with 1 <= k <= 8 (R_y >= R_x), U varied over nearly two orders of magnitude and W
over one, bronze, steel and silicon nitride with paraffinic and naphthenic mineral oils. Outside (k < 1: entrainment along
the long axis, as on a corner contact sliding along its parallel circle; high-speed inlet
heating; starvation) the formula is extrapolated: the values follow it, their accuracy is not
claimed.

Regularisation (everything C-infinity and finite at zero speed and zero load): the entrainment
speed enters as sqrt(u_e^2 + u_eps^2), u_eps = `SLIDING_EPS` (1 mm/s: a nanometre-scale film,
so Lambda ~ 0 and the contact is boundary-lubricated at rest); the load as the smooth maximum
Q_f (1 + softplus(Q/Q_f - 1)), Q_f = `FILM_LOAD_FLOOR` = 1 mN, which tends to Q above Q_f and to
Q_f (not 0) below (H ~ W^-0.07 diverges at zero load; the floor changes the film by less than
1e-6 relative above 10 mN, and the traction it feeds is multiplied by Q); the composite
roughness as sqrt(s_1^2 + s_2^2 + s_f^2), s_f = 1e-12 m (1.4e-11 relative at 0.19 um).

Film parameter and mixed lubrication. Lambda = h_min / sqrt(s_1^2 + s_2^2) with the rms
roughnesses of both surfaces (Tallian 1967; Hamrock 2004). The load is shared between asperity
contact and the film (Johnson, Greenwood & Poon, "A simple theory of asperity contact in
elastohydrodynamic lubrication", Wear 19:91-108, 1972). This module uses the asperity share

    f_a(Lambda) = 1 / (1 + (Lambda / Lambda_m)^6),    Lambda_m = 3^(1/3) = 1.442,

a log-logistic step chosen for this implementation (not a published fit) so that the
asperities carry 90 % of the load at Lambda = 1 and 1.2 % (1/82) at Lambda = 3, the usual
limits of boundary (Lambda < 1) and full-film (Lambda > 3) lubrication (Hamrock, Schmid &
Jacobson 2004, ch. 1; Harris & Kotzalas 2006). It is 1 at Lambda = 0 with zero slope and a
polynomial in Lambda, so C-infinity for Lambda >= 0. The traction coefficient blends

    mu = f_a mu_b + (1 - f_a) kappa(|u|),

the boundary coefficient mu_b of the dry/boundary contact and the full-film EHL traction curve
kappa of the lubricant (`traction_coefficient`, docs/model.md 8). A Zhou & Hoeprich (1991) type
load-sharing fit was considered; its coefficients could not be verified from the sources
available here, so it is not used.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import jax
import jax.numpy as jnp
from jaxtyping import Array, ArrayLike, Float

from ._hertz import point_contact_ellipticity
from ._smooth import SLIDING_EPS
from ._traction import traction_coefficient

if TYPE_CHECKING:  # annotations only: contact laws sit below the parameter layer
    from ..geometry import Lubricant

#: Smooth floor of the load in the film formulas [N] (see the module docstring).
FILM_LOAD_FLOOR = 1e-3

#: Floor of the composite roughness [m] (keeps Lambda finite for ideally smooth surfaces).
ROUGHNESS_FLOOR = 1e-12

#: Lambda at which the asperities carry half the load in `asperity_load_fraction`: 3^(1/3).
ASPERITY_MIDPOINT = 3.0 ** (1.0 / 3.0)

#: Exponent of the asperity load share f_a = 1 / (1 + (Lambda/Lambda_m)^6).
ASPERITY_EXPONENT = 6

# Hamrock & Dowson (1977): coefficient, exponents of U, G, W, and the ellipticity factor
_MIN = (3.63, 0.68, 0.49, -0.073, 1.0, 0.68)
_CENTRAL = (2.69, 0.67, 0.53, -0.067, 0.61, 0.73)


def viscosity_at_temperature(
    temperature: Float[ArrayLike, "*#batch"],
    reference_viscosity: Float[ArrayLike, "*#batch"],
    temperature_viscosity: Float[ArrayLike, "*#batch"],
    reference_temperature: Float[ArrayLike, "*#batch"],
) -> Float[Array, "*batch"]:
    """Dynamic viscosity eta = eta_0 exp(-beta_T (T - T_0)) [Pa s] (Reynolds' exponential law).

    Args:
        temperature: T (same unit as T_0, K or C).
        reference_viscosity: eta_0 [Pa s] at T_0 (`Lubricant.viscosity`).
        temperature_viscosity: beta_T [1/K] (`Lubricant.temperature_viscosity`).
        reference_temperature: T_0.
    """
    dt = jnp.asarray(temperature) - jnp.asarray(reference_temperature)
    return jnp.asarray(reference_viscosity) * jnp.exp(-jnp.asarray(temperature_viscosity) * dt)


def entrainment_velocity(
    surface_velocity_1: Float[ArrayLike, "*#batch dim"],
    surface_velocity_2: Float[ArrayLike, "*#batch dim"],
) -> Float[Array, "*batch dim"]:
    """Mean entrainment velocity u_e = (u_1 + u_2) / 2 [m/s] (Hamrock & Dowson 1977).

    u_1, u_2: tangential velocities of the two surfaces RELATIVE TO THE CONTACT POINT (the
    material velocity of each body at the contact minus the velocity with which the contact
    point itself moves). Their difference is the sliding velocity.
    """
    return 0.5 * (jnp.asarray(surface_velocity_1) + jnp.asarray(surface_velocity_2))


def entrainment_radii(
    radius_1: Float[ArrayLike, "*#batch"],
    radius_2: Float[ArrayLike, "*#batch"],
    cos_angle: Float[ArrayLike, "*#batch"],
) -> tuple[Float[Array, "*batch"], Float[Array, "*batch"]]:
    """Effective radii (R_x, R_y) along and across the entrainment direction [m].

    Euler's theorem for the normal curvature of the gap: 1/R_x = c^2/R_1 + s^2/R_2,
    1/R_y = s^2/R_1 + c^2/R_2, c = cos of the angle between the entrainment direction and
    principal direction 1, s^2 = 1 - c^2. Exact for c^2 in {0, 1}; otherwise it drops the twist
    term of the gap and so treats the ellipse as aligned with the entrainment (an approximation,
    as is applying Hamrock & Dowson's aligned formulas to a skewed contact).
    """
    c2 = jnp.square(jnp.asarray(cos_angle))
    k1, k2 = 1.0 / jnp.asarray(radius_1), 1.0 / jnp.asarray(radius_2)
    return 1.0 / (c2 * k1 + (1.0 - c2) * k2), 1.0 / ((1.0 - c2) * k1 + c2 * k2)


def ehl_parameters(
    load: Float[ArrayLike, "*#batch"],
    radius_x: Float[ArrayLike, "*#batch"],
    radius_y: Float[ArrayLike, "*#batch"],
    entrainment_speed: Float[ArrayLike, "*#batch"],
    e_prime: Float[ArrayLike, "*#batch"],
    viscosity: Float[ArrayLike, "*#batch"],
    pressure_viscosity: Float[ArrayLike, "*#batch"],
    speed_eps: Float[ArrayLike, "*#batch"] = SLIDING_EPS,
) -> tuple[Float[Array, "*batch"], Float[Array, "*batch"], Float[Array, "*batch"], Float[Array, "*batch"]]:
    """Hamrock & Dowson's dimensionless (U, G, W, k) of an elliptical EHL contact.

    U = eta u / (E' R_x) with u = sqrt(u_e^2 + u_eps^2), G = alpha_p E',
    W = Q_f (1 + softplus(Q/Q_f - 1)) / (E' R_x^2), k = a_y/a_x = 1/`point_contact_ellipticity`
    (exact Hertz). Arguments as in `minimum_film_thickness`.
    """
    q = FILM_LOAD_FLOOR * (1.0 + jax.nn.softplus(jnp.asarray(load) / FILM_LOAD_FLOOR - 1.0))
    u = jnp.sqrt(jnp.square(jnp.asarray(entrainment_speed)) + jnp.square(speed_eps))
    radius_x = jnp.asarray(radius_x)
    e_prime = jnp.asarray(e_prime)
    speed = jnp.asarray(viscosity) * u / (e_prime * radius_x)
    materials = jnp.asarray(pressure_viscosity) * e_prime
    load_parameter = q / (e_prime * radius_x * radius_x)
    ellipticity = 1.0 / point_contact_ellipticity(radius_x, radius_y)
    return speed, materials, load_parameter, ellipticity


def _film(
    coefficients,
    load,
    radius_x,
    radius_y,
    entrainment_speed,
    e_prime,
    viscosity,
    pressure_viscosity,
    speed_eps,
):
    c, nu, ng, nw, a, b = coefficients
    u, g, w, k = ehl_parameters(
        load, radius_x, radius_y, entrainment_speed, e_prime, viscosity, pressure_viscosity, speed_eps
    )
    shape = 1.0 - a * jnp.exp(-b * k)
    return c * u**nu * g**ng * w**nw * shape * jnp.asarray(radius_x)


def minimum_film_thickness(
    load: Float[ArrayLike, "*#batch"],
    radius_x: Float[ArrayLike, "*#batch"],
    radius_y: Float[ArrayLike, "*#batch"],
    entrainment_speed: Float[ArrayLike, "*#batch"],
    e_prime: Float[ArrayLike, "*#batch"],
    viscosity: Float[ArrayLike, "*#batch"],
    pressure_viscosity: Float[ArrayLike, "*#batch"],
    speed_eps: Float[ArrayLike, "*#batch"] = SLIDING_EPS,
) -> Float[Array, "*batch"]:
    """Hamrock-Dowson (1977) minimum EHL film h_min = R_x 3.63 U^0.68 G^0.49 W^-0.073
    (1 - exp(-0.68 k)) [m] (module docstring: validity, regularisation).

    Args:
        load: normal load Q [N] (>= 0; floored smoothly at `FILM_LOAD_FLOOR`).
        radius_x: effective radius along the entrainment direction [m].
        radius_y: effective radius across it [m] (`entrainment_radii` for a skewed contact).
        entrainment_speed: u_e = |u_1 + u_2|/2 [m/s] (`entrainment_velocity`; its sign is
            ignored, and it is regularised as sqrt(u_e^2 + u_eps^2)).
        e_prime: E' [Pa] (`effective_modulus`).
        viscosity: eta [Pa s] at the inlet temperature (`viscosity_at_temperature`).
        pressure_viscosity: alpha_p [1/Pa] (> 0).
        speed_eps: u_eps [m/s].
    """
    return _film(
        _MIN, load, radius_x, radius_y, entrainment_speed, e_prime, viscosity, pressure_viscosity, speed_eps
    )


def central_film_thickness(
    load: Float[ArrayLike, "*#batch"],
    radius_x: Float[ArrayLike, "*#batch"],
    radius_y: Float[ArrayLike, "*#batch"],
    entrainment_speed: Float[ArrayLike, "*#batch"],
    e_prime: Float[ArrayLike, "*#batch"],
    viscosity: Float[ArrayLike, "*#batch"],
    pressure_viscosity: Float[ArrayLike, "*#batch"],
    speed_eps: Float[ArrayLike, "*#batch"] = SLIDING_EPS,
) -> Float[Array, "*batch"]:
    """Hamrock-Dowson central EHL film h_c = R_x 2.69 U^0.67 G^0.53 W^-0.067
    (1 - 0.61 exp(-0.73 k)) [m]. Arguments as in `minimum_film_thickness`."""
    return _film(
        _CENTRAL,
        load,
        radius_x,
        radius_y,
        entrainment_speed,
        e_prime,
        viscosity,
        pressure_viscosity,
        speed_eps,
    )


def film_parameter(
    film_thickness: Float[ArrayLike, "*#batch"],
    roughness_1: Float[ArrayLike, "*#batch"],
    roughness_2: Float[ArrayLike, "*#batch"],
) -> Float[Array, "*batch"]:
    """Film parameter Lambda = h / sqrt(s_1^2 + s_2^2 + s_f^2) (Tallian 1967; Hamrock 2004).

    Args:
        film_thickness: h [m], normally `minimum_film_thickness`.
        roughness_1, roughness_2: rms roughnesses R_q of the two surfaces [m].
    The floor s_f = `ROUGHNESS_FLOOR` only matters for ideally smooth surfaces.
    """
    sigma2 = jnp.square(jnp.asarray(roughness_1)) + jnp.square(jnp.asarray(roughness_2)) + ROUGHNESS_FLOOR**2
    return jnp.asarray(film_thickness) / jnp.sqrt(sigma2)


def asperity_load_fraction(
    film_parameter: Float[ArrayLike, "*#batch"],
    midpoint: Float[ArrayLike, "*#batch"] = ASPERITY_MIDPOINT,
) -> Float[Array, "*batch"]:
    """Share of the load carried by asperity contact, f_a = 1 / (1 + (Lambda/Lambda_m)^6).

    A smooth step, chosen for this implementation (module docstring), from boundary lubrication
    (f_a = 0.9 at Lambda = 1) to full film (f_a = 1/82 at Lambda = 3) with the default
    Lambda_m = 3^(1/3); 1 with zero slope at Lambda = 0.
    """
    x = jnp.asarray(film_parameter) / midpoint
    return 1.0 / (1.0 + x**ASPERITY_EXPONENT)


def mixed_traction_coefficient(
    film_parameter: Float[ArrayLike, "*#batch"],
    boundary_coefficient: Float[ArrayLike, "*#batch"],
    full_film_coefficient: Float[ArrayLike, "*#batch"],
    midpoint: Float[ArrayLike, "*#batch"] = ASPERITY_MIDPOINT,
) -> Float[Array, "*batch"]:
    """Mixed-lubrication traction coefficient mu = f_a mu_b + (1 - f_a) mu_EHL.

    f_a = `asperity_load_fraction`(Lambda) (load sharing, Johnson, Greenwood & Poon 1972).

    Args:
        film_parameter: Lambda (`film_parameter`).
        boundary_coefficient: mu_b of asperity (boundary) contact, e.g. the paper's flange
            friction coefficient 0.08 (`Bearing.flange_traction`).
        full_film_coefficient: mu_EHL of the full film, e.g. the lubricant traction curve
            `traction_coefficient(|u|, lubricant)`.
        midpoint: Lambda_m of the load share.
    """
    f = asperity_load_fraction(film_parameter, midpoint)
    return f * jnp.asarray(boundary_coefficient) + (1.0 - f) * jnp.asarray(full_film_coefficient)


def mixed_traction_force(
    sliding_velocity: Float[ArrayLike, "*batch dim"],
    normal_load: Float[ArrayLike, "*#batch"],
    film_parameter: Float[ArrayLike, "*#batch"],
    boundary_coefficient: Float[ArrayLike, "*#batch"],
    lubricant: Lubricant,
    speed_eps: Float[ArrayLike, "*#batch"] = SLIDING_EPS,
) -> Float[Array, "*batch dim"]:
    """Traction of a mixed-lubricated contact F = -Q mu(Lambda, s) u / s [N].

    s = sqrt(|u|^2 + u_eps^2), mu = `mixed_traction_coefficient` with the lubricant's traction
    curve kappa(s) (docs/model.md 8) as the full-film part. Opposes the sliding velocity u (last
    axis: components), vanishes smoothly at u = 0 and with the load.

    Args:
        sliding_velocity: u [m/s], velocity of the body the force acts on relative to the other
            body at the contact point, tangential components.
        normal_load: Q >= 0 [N].
        film_parameter: Lambda of the contact.
        boundary_coefficient: mu_b.
        lubricant: supplies the traction curve (`traction_coefficient`).
        speed_eps: u_eps [m/s].
    """
    u = jnp.asarray(sliding_velocity)
    s = jnp.sqrt(jnp.sum(u * u, axis=-1) + jnp.square(speed_eps))
    mu = mixed_traction_coefficient(film_parameter, boundary_coefficient, traction_coefficient(s, lubricant))
    return -(jnp.asarray(normal_load) * mu / s)[..., None] * u
