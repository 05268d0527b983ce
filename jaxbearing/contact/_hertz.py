"""Hertz point contact: effective modulus, stiffness, contact ellipse, peak pressure, approach.

Closed-form approximations of Hamrock & Brewe (1983), "Simplified solution for stresses and
deformations", J. Lubr. Technol. 105:171-177 (also Hamrock, Schmid & Jacobson, Fundamentals
of Machine Elements, ch. 8; Harris & Kotzalas, Essential Concepts of Bearing Technology,
ch. 6). With the effective principal radii R_x, R_y of the pair (the caller sums curvatures),
the curvature ratio alpha_r = R_large / R_small >= 1, R = 1 / (1/R_x + 1/R_y), and the
effective modulus E' = 2 / ((1 - nu_1^2)/E_1 + (1 - nu_2^2)/E_2):

    k   = 1.0339 alpha_r^0.6360                 ellipticity a/b (long over short semi-axis)
    Ecal = 1.0003 + 0.5968 / alpha_r            elliptic integral of the second kind
    Fcal = 1.5277 + 0.6023 ln(alpha_r)          elliptic integral of the first kind
    a   = (6 k^2 Ecal Q R / (pi E'))^(1/3)      long semi-axis, along the LARGER radius
    b   = (6 Ecal Q R / (pi k E'))^(1/3)        short semi-axis
    delta = Fcal (9/(2 Ecal R) (Q / (pi k E'))^2)^(1/3)
    Q   = K delta^(3/2),  K = pi k E' sqrt(Ecal R / (4.5 Fcal^3))    (as in the paper's flange law)
    p_max = 3 Q / (2 pi a b)

The exact solution (Johnson, Contact Mechanics, 1985, sec. 4.2) replaces k, Ecal, Fcal by the
root of B/A = (k^2 E(e) - K(e)) / (K(e) - E(e)), e^2 = 1 - 1/k^2, and the complete elliptic
integrals K(e), E(e); the tests compare against it with scipy.

Accuracy of the fit. Hamrock & Brewe fitted these expressions over 1 <= alpha_r <= 100. Over
that range the fitted k, Ecal, Fcal deviate from the exact values by at most 6.4 %, 1.7 % and
2.8 % (k at alpha_r = 100; Ecal and Fcal at alpha_r = 1, where the fit gives 1.0339, 1.5971,
1.5277 against 1, pi/2, pi/2; the text of the 1983 paper was not available to this
implementation, so these figures are the published coefficients evaluated against the exact
solution). The derived quantities inherit: the approach delta is 5.4 % low and the stiffness
8.7 % high at alpha_r = 1, p_max is within 2.2 %. Outside the fitted range the fit degrades
(at alpha_r = 1e3: stiffness +21 %, p_max -7 %; at 1e4: +43 %, -13 %). See
`HAMROCK_BREWE_ERROR` for the per-quantity bounds the tests assert.

Smoothness. ln(alpha_r) = |ln(R_x/R_y)| has a kink at R_x = R_y, and the fit is not flat there
(k(1) = 1.0339), so |.| is replaced by t tanh(t / 0.01), t = ln(R_x/R_y): exact at t = 0 and
equal to |t| to 1e-4 relative once the radii differ by 5 %; it makes every function here C-inf
and exactly symmetric in R_x <-> R_y. The orientation of the ellipse turns smoothly in the same
window, so at R_x = R_y the ellipse is a circle of area pi a b. Very large ratios (a torus
against a plane gives up to ~1e4; a flat face gives infinity) are saturated smoothly at
`MAX_CURVATURE_RATIO` (a softplus in ln alpha_r of width 0.5: the ratio is changed by less
than 1e-8 relative up to alpha_r = 1e4).

Loads at or below `LOAD_FLOOR` count as no contact in the load-driven functions (semi-axes,
p_max, approach are 0 with zero derivatives), which keeps Q^(1/3) and Q^(2/3) twice
differentiable at Q = 0.
"""

from __future__ import annotations

import math

import jax
import jax.numpy as jnp
from jaxtyping import Array, ArrayLike, Float

#: Saturation of the curvature ratio R_large / R_small (smooth; see the module docstring).
MAX_CURVATURE_RATIO = 1e8

#: Loads [N] at or below this are treated as no contact by the load-driven functions.
LOAD_FLOOR = 1e-30

#: Largest relative error of the Hamrock & Brewe (1983) fit against the exact Hertz solution
#: over its fitted range 1 <= R_large/R_small <= 100 (published coefficients evaluated against
#: the exact elliptic-integral solution, see the module docstring). Keys: ellipticity k,
#: second-kind integral Ecal, first-kind integral Fcal.
HAMROCK_BREWE_ERROR = {"ellipticity": 0.064, "second_kind": 0.017, "first_kind": 0.028}

_K_COEF, _K_EXP = 1.0339, 0.6360
_E_0, _E_1 = 1.0003, 0.5968
_F_0, _F_1 = 1.5277, 0.6023
_RATIO_SMOOTHING = 1e-2  # width of the smooth |ln(Rx/Ry)| and of the orientation switch
_LN_MAX_RATIO = math.log(MAX_CURVATURE_RATIO)
_SATURATION_WIDTH = 0.5  # in ln(alpha_r)


def effective_modulus(
    e1: Float[ArrayLike, "*#batch"],
    nu1: Float[ArrayLike, "*#batch"],
    e2: Float[ArrayLike, "*#batch"],
    nu2: Float[ArrayLike, "*#batch"],
) -> Float[Array, "*batch"]:
    """Effective modulus E' = 2 / ((1 - nu1^2)/E1 + (1 - nu2^2)/E2) [Pa].

    Hamrock's convention (Hamrock & Brewe 1983): E' = 2 E*, with the contact modulus of
    Johnson (Contact Mechanics, sec. 4.2) 1/E* = (1-nu1^2)/E1 + (1-nu2^2)/E2. For two identical
    bodies E' = E / (1 - nu^2).
    """
    return 2.0 / ((1.0 - jnp.square(nu1)) / e1 + (1.0 - jnp.square(nu2)) / e2)


def _fit(radius_x, radius_y):
    """Shared pieces of the Hamrock-Brewe fit: (R, ln alpha_r, signed orientation, k, Ecal, Fcal).

    t = ln(R_x/R_y) (hard-clipped far beyond the saturation so that infinite radii give
    finite values and zero, not NaN, derivatives); ln alpha_r = sat(t tanh(t/w)); the
    orientation s = tanh(t/w) in [-1, 1] is +1 when R_x is the larger radius.
    """
    radius_x = jnp.asarray(radius_x)
    radius_y = jnp.asarray(radius_y)
    radius = 1.0 / (1.0 / radius_x + 1.0 / radius_y)
    t = jnp.clip(jnp.log(radius_x) - jnp.log(radius_y), -2 * _LN_MAX_RATIO, 2 * _LN_MAX_RATIO)
    orientation = jnp.tanh(t / _RATIO_SMOOTHING)
    ln_ratio = t * orientation  # smooth |t|
    # smooth min(ln_ratio, ln max): exact below, saturates above (softplus of width 1)
    ln_ratio = _LN_MAX_RATIO - _SATURATION_WIDTH * jax.nn.softplus(
        (_LN_MAX_RATIO - ln_ratio) / _SATURATION_WIDTH
    )
    ellipticity = _K_COEF * jnp.exp(_K_EXP * ln_ratio)
    second_kind = _E_0 + _E_1 * jnp.exp(-ln_ratio)
    first_kind = _F_0 + _F_1 * ln_ratio
    return radius, orientation, ellipticity, second_kind, first_kind


def hamrock_brewe_parameters(
    radius_x: Float[ArrayLike, "*#batch"], radius_y: Float[ArrayLike, "*#batch"]
) -> tuple[Float[Array, "*batch"], Float[Array, "*batch"], Float[Array, "*batch"]]:
    """(k, Ecal, Fcal): ellipticity and elliptic integrals of the Hamrock & Brewe (1983) fit.

    k = 1.0339 alpha_r^0.6360, Ecal = 1.0003 + 0.5968/alpha_r, Fcal = 1.5277 + 0.6023 ln alpha_r,
    alpha_r = R_large/R_small (smoothed at alpha_r = 1, saturated at `MAX_CURVATURE_RATIO`).
    """
    _, _, k, e, f = _fit(radius_x, radius_y)
    return k, e, f


def point_contact_stiffness(
    radius_x: Float[ArrayLike, "*#batch"],
    radius_y: Float[ArrayLike, "*#batch"],
    e_prime: Float[ArrayLike, "*#batch"],
) -> Float[Array, "*batch"]:
    """Hertz point-contact stiffness K with Q = K delta^(3/2) [N/m^1.5].

    K = pi k E' sqrt(Ecal R / (4.5 Fcal^3)) (Hamrock & Brewe 1983; the paper's flange stiffness),
    R = 1/(1/R_x + 1/R_y). Symmetric in R_x <-> R_y, C-infinity in both radii including
    R_x = R_y, finite for ratios up to and beyond `MAX_CURVATURE_RATIO` (saturated).

    Args:
        radius_x, radius_y: effective principal radii of curvature of the pair [m] (positive,
            convex; the caller sums the curvatures of both bodies per direction).
        e_prime: effective modulus E' [Pa] (`effective_modulus`).
    """
    radius, _, k, e, f = _fit(radius_x, radius_y)
    return jnp.pi * k * e_prime * jnp.sqrt(e * radius / (4.5 * f**3))


def _safe_load(load):
    load = jnp.asarray(load)
    loaded = load > LOAD_FLOOR
    return loaded, jnp.where(loaded, load, 1.0)


def point_contact_ellipse(
    load: Float[ArrayLike, "*#batch"],
    radius_x: Float[ArrayLike, "*#batch"],
    radius_y: Float[ArrayLike, "*#batch"],
    e_prime: Float[ArrayLike, "*#batch"],
) -> tuple[Float[Array, "*batch"], Float[Array, "*batch"]]:
    """Semi-axes (a_x, a_y) of the Hertz contact ellipse along the x and y directions [m].

    Long semi-axis a = (6 k^2 Ecal Q R/(pi E'))^(1/3) along the direction of the LARGER radius,
    short semi-axis b = (6 Ecal Q R/(pi k E'))^(1/3) along the smaller one (Hamrock & Brewe
    1983). Written as a_x = sqrt(a b) k_x^(1/2), a_y = sqrt(a b) k_x^(-1/2) with the signed
    ellipticity ln k_x = tanh(ln(R_x/R_y)/0.01) ln k, which turns the ellipse smoothly through a
    circle when the radii cross. Zero (with zero derivatives) for Q <= `LOAD_FLOOR`.
    """
    loaded, q = _safe_load(load)
    radius, orientation, k, e, _ = _fit(radius_x, radius_y)
    # sqrt(a b) = (6 Ecal Q R / (pi E'))^(1/3) k^(1/6)
    mean = (6.0 * e * q * radius / (jnp.pi * e_prime)) ** (1.0 / 3.0) * k ** (1.0 / 6.0)
    half_ln_kx = 0.5 * orientation * jnp.log(k)
    a_x = jnp.where(loaded, mean * jnp.exp(half_ln_kx), 0.0)
    a_y = jnp.where(loaded, mean * jnp.exp(-half_ln_kx), 0.0)
    return a_x, a_y


def point_contact_peak_pressure(
    load: Float[ArrayLike, "*#batch"],
    radius_x: Float[ArrayLike, "*#batch"],
    radius_y: Float[ArrayLike, "*#batch"],
    e_prime: Float[ArrayLike, "*#batch"],
) -> Float[Array, "*batch"]:
    """Peak Hertz pressure p_max = 3 Q / (2 pi a b) [Pa] (Hamrock & Brewe 1983; the paper's
    p_max of the roller-flange contacts). Zero (with zero derivatives) for Q <= `LOAD_FLOOR`."""
    loaded, q = _safe_load(load)
    radius, _, k, e, _ = _fit(radius_x, radius_y)
    # a b = (6 Ecal Q R / (pi E'))^(2/3) k^(1/3)
    ab = (6.0 * e * q * radius / (jnp.pi * e_prime)) ** (2.0 / 3.0) * k ** (1.0 / 3.0)
    return jnp.where(loaded, 3.0 * q / (2.0 * jnp.pi * ab), 0.0)


def point_contact_deflection(
    load: Float[ArrayLike, "*#batch"],
    radius_x: Float[ArrayLike, "*#batch"],
    radius_y: Float[ArrayLike, "*#batch"],
    e_prime: Float[ArrayLike, "*#batch"],
) -> Float[Array, "*batch"]:
    """Elastic approach delta = (Q / K)^(2/3) [m], the inverse of `point_contact_stiffness`'s law.

    Equal to Fcal (9/(2 Ecal R) (Q/(pi k E'))^2)^(1/3) (Hamrock & Brewe 1983). Zero (with zero
    derivatives) for Q <= `LOAD_FLOOR`.
    """
    loaded, q = _safe_load(load)
    stiffness = point_contact_stiffness(radius_x, radius_y, e_prime)
    return jnp.where(loaded, (q / stiffness) ** (2.0 / 3.0), 0.0)
