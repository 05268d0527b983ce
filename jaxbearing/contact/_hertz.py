"""Hertz point contact: effective modulus, stiffness, contact ellipse, peak pressure, approach.

Exact Hertz solution (Johnson, Contact Mechanics, 1985, sec. 4.2; Harris & Kotzalas, Essential
Concepts of Bearing Technology, 2006, ch. 6). With the effective principal radii R_x, R_y of the
pair (the caller sums the curvatures of both bodies per direction), R = 1/(1/R_x + 1/R_y) and
the effective modulus E' = 2 / ((1 - nu_1^2)/E_1 + (1 - nu_2^2)/E_2) (Hamrock's convention,
E' = 2 E*), the contact ellipse has semi-axes a_x, a_y along x and y, and Johnson's relations for
the ellipsoidal pressure on a half-space, with m = 1 - (a_y/a_x)^2 and the complete elliptic
integrals K(m), E(m) (parameter m, not modulus), give

    R_x / R_y = (k^2 E(m) - K(m)) / (K(m) - E(m)),      k = a_x / a_y = (1 - m)^(-1/2)   (1)
    a_y = (6 E(m) Q R / (pi k E'))^(1/3),   a_x = k a_y
    delta = K(m) (9 / (2 E(m) R) (Q / (pi k E'))^2)^(1/3)
    Q = K_s delta^(3/2),   K_s = pi k E' sqrt(E(m) R / (4.5 K(m)^3))
    p_max = 3 Q / (2 pi a_x a_y)

These are Hamrock & Brewe's (1983) closed forms with their fitted k, Ecal, Fcal replaced by the
exact k, E(m), K(m): the fit, kept as `hamrock_brewe_parameters` for comparison, is 12 % too
stiff and 4 % low in p_max at the corner contact's ratio R_large/R_small ~ 300.

Signed ellipticity. Relation (1) is written for k = a_x/a_y of EITHER sign of ln k: for
R_x < R_y, m < 0, and the elliptic integrals of negative parameter (K(m) = K(m')/k',
E(m) = k' E(m'), m' = m/(m - 1), the imaginary-modulus transformation) turn every formula
above into the usual one with the axes swapped. So one analytic law covers both orientations
and the crossing R_x = R_y, where the ellipse turns through a circle: every quantity is a real
analytic (C-infinity) function of ln(R_x/R_y), exactly symmetric in R_x <-> R_y, with no
|ln(R_x/R_y)| kink and no smoothing window.

Solving (1). With lambda = ln k and t = ln(R_x/R_y), (1) reads
T(lambda) = 2 lambda + ln((1 - S)/S) = t with S = (K - E)/(m K); T is odd and increasing, with
slope T' = 2 - (S^2 - 2R)/(S (1 - S)) between 3/2 (at the circle) and 2 (R defined below) and
small curvature, so Newton's method converges quadratically from anywhere. The initial guess

    lambda_0 = t/2 + 0.4789 asinh(t/3.288) + 0.02373 t/(1 + 0.04211 t^2)
               - 0.002710 t/(1 + 0.02945 t^2)^2

(odd in t; coefficients to 10 digits in the code, fitted for this implementation to the exact
root over |t| <= 20, i.e. ratios up to 5e8; its error is below 3.2e-6 in lambda) is followed by
ONE Newton step, which leaves an error below 3e-13 in lambda (T''/(2T') times the square of the
guess error; measured against scipy over the same range). K and E, computed by the AGM at
lambda_0 for that step, are carried to the new lambda by their Taylor series to second order in
the step d (dK/dlambda = K (1 - S), dE/dlambda = -K S (1 - m), dS/dlambda = S^2 - 2R, so the
second derivatives are K ((1 - S)^2 - S^2 + 2R) and K (1 - m) (S + 2R)): error O(d^3) ~ 1e-17,
and k = exp(lambda_0 + d) likewise. So the law costs one AGM per evaluation, with no loop. The
derivatives come from the implicit-function theorem (`jax.custom_jvp`: d lambda = dt / T'(lambda),
dK = K (1 - S) d lambda, dE = -K S (1 - m) d lambda), so gradients and Hessians are those of
the exact solution, not of the approximation steps.

Elliptic integrals by the arithmetic-geometric mean (Abramowitz & Stegun 17.6; `AGM_STEPS` = 7
steps, double precision up to k = 4e4, i.e. ratios 1e8): a_0 = 1, b_0 = sqrt(1-m) = exp(-lambda),
a_{n+1} = (a_n + b_n)/2, b_{n+1} = sqrt(a_n b_n), K = pi/(2 a_inf),
E = K (1 - sum_n 2^(n-1) c_n^2), c_0^2 = m, c_{n+1} = c_n^2/(4 a_{n+1}). The sum is carried as
S = sum 2^(n-1) c_n^2/m = 1/2 + m R, R = sum_{n>=1} 2^(n-1) c_n^2/m^2, through s_n = c_n^2/m,
r_n = s_n/m, r_{n+1} = s_n^2/(16 a_{n+1}^2), s_{n+1} = m r_{n+1}: no step divides by m, so
K - E = m K S, E - (1 - m) K = m K (1 - S) and relation (1), k^2 (1 - S)/S, are regular at the
circle. b_0 = exp(-lambda) keeps full relative precision as m -> 1 (slender ellipses), where
1 - m would round.

Very large ratios (a torus against a plane gives up to ~1e4, and more as the flange normal
approaches the roller axis; a flat face gives infinity) are saturated smoothly at
`MAX_CURVATURE_RATIO`: t -> t / (1 + (t/L)^32)^(1/32), L = ln(MAX_CURVATURE_RATIO), an odd
C-infinity function that changes ratios up to 1e4 by less than 1e-10 relative (5e-5 at 1e6);
t is hard-clipped at +-2L first so that infinite radii give finite values and zero (not NaN)
derivatives.

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
#: the exact elliptic-integral solution). Keys: ellipticity k, second-kind integral Ecal,
#: first-kind integral Fcal. Applies to `hamrock_brewe_parameters` only.
HAMROCK_BREWE_ERROR = {"ellipticity": 0.064, "second_kind": 0.017, "first_kind": 0.028}

#: Arithmetic-geometric-mean steps of the elliptic integrals (double precision up to k = 4e4).
AGM_STEPS = 7


_K_COEF, _K_EXP = 1.0339, 0.6360
_E_0, _E_1 = 1.0003, 0.5968
_F_0, _F_1 = 1.5277, 0.6023
_RATIO_SMOOTHING = 1e-2  # width of the fit's smooth |ln(Rx/Ry)| (hamrock_brewe_parameters only)
_LN_MAX_RATIO = math.log(MAX_CURVATURE_RATIO)
_SATURATION_WIDTH = 0.5  # in ln(alpha_r), of the fit's saturation (hamrock_brewe_parameters)
# initial guess of ln(a_x/a_y) (module docstring): fitted to the exact root over |t| <= 20
_G_ASINH, _G_ASINH_SCALE = 0.4789132974, 3.288391516
_G_RAT1, _G_RAT1_SCALE = 0.02373464235, 0.04211023427
_G_RAT2, _G_RAT2_SCALE = -0.002709848193, 0.02945086781


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


# ------------------------------------------------------------------ elliptic integrals (AGM)
def _agm(log_ellipticity):
    """(m, b_0, a_inf, S, R) of the AGM started at (1, b_0 = exp(-lambda)) (module docstring).

    m = 1 - b_0^2; a_inf = AGM(1, b_0), so K(m) = pi / (2 a_inf); S = (K - E)/(m K) =
    sum_{n>=0} 2^(n-1) c_n^2 / m = 1/2 + m R with R = sum_{n>=1} 2^(n-1) c_n^2 / m^2. With
    s_n = c_n^2/m and r_n = s_n/m: s_0 = 1, r_{n+1} = s_n^2 / (16 a_{n+1}^2), s_{n+1} = m r_{n+1}
    (from c_{n+1} = c_n^2 / (4 a_{n+1})). No step divides by m, so everything is regular at the
    circle m = 0 (S = 1/2, R = 1/16) and valid for any real lambda (m in (-inf, 1)).
    """
    lam = jnp.asarray(log_ellipticity)
    e1 = jnp.expm1(-lam)  # b_0 - 1, exact near the circle
    b0 = 1.0 + e1
    m = -e1 * (2.0 + e1)  # 1 - b_0^2 = (1 - b_0)(1 + b_0)

    def step(carry, _):
        a, b, s, weight, total = carry
        a_next = 0.5 * (a + b)
        b_next = jnp.sqrt(a * b)
        r_next = s * s / (16.0 * a_next * a_next)
        return (a_next, b_next, m * r_next, 2.0 * weight, total + weight * r_next), None

    one = jnp.ones_like(lam)
    init = (one, b0, one, one, jnp.zeros_like(lam))
    (a, _, _, _, total), _ = jax.lax.scan(step, init, None, length=AGM_STEPS, unroll=True)
    return m, b0, a, 0.5 + m * total, total


def _elliptic_from_log_ellipticity(log_ellipticity):
    """(m, b_0, K(m), E(m), S, R) for b_0 = exp(-lambda), m = 1 - b_0^2, by the AGM (`_agm`)."""
    m, b0, a, s, r = _agm(log_ellipticity)
    first = 0.5 * jnp.pi / a
    second = first * (1.0 - m * s)
    return m, b0, first, second, s, r


def complete_elliptic_integrals(
    m: Float[ArrayLike, "*batch"],
) -> tuple[Float[Array, "*batch"], Float[Array, "*batch"]]:
    """Complete elliptic integrals (K(m), E(m)) of parameter m < 1 (A&S 17.3.1, 17.3.3).

    K(m) = int_0^(pi/2) (1 - m sin^2 t)^(-1/2) dt, E(m) = int_0^(pi/2) (1 - m sin^2 t)^(1/2) dt,
    by the arithmetic-geometric mean with `AGM_STEPS` steps (Abramowitz & Stegun 17.6),
    differentiable, for any m < 1 including m < 0. Matches scipy.special.ellipk/ellipe to
    double precision for 1 - m >= 1e-9 (beyond, 1 - m itself rounds; the Hertz functions avoid
    that by working from k).
    """
    m = jnp.asarray(m)
    lam = -0.5 * jnp.log1p(-m)  # sqrt(1 - m) = exp(-lambda)
    _, _, first, second, _, _ = _elliptic_from_log_ellipticity(lam)
    return first, second


# ----------------------------------------------------------------- ellipticity from radii
def _ratio_log_slope(s, r):
    """dT/dlambda = 2 - (S^2 - 2R) / (S (1 - S)) (module docstring; 3/2 at the circle)."""
    return 2.0 - (s * s - 2.0 * r) / (s * (1.0 - s))


def _initial_guess(log_ratio):
    """lambda_0(t), odd in t, within 3.2e-6 of the root of (1) for |t| <= 20 (module docstring)."""
    t = jnp.asarray(log_ratio)
    t2 = t * t
    return (
        0.5 * t
        + _G_ASINH * jnp.arcsinh(t / _G_ASINH_SCALE)
        + _G_RAT1 * t / (1.0 + _G_RAT1_SCALE * t2)
        + _G_RAT2 * t / jnp.square(1.0 + _G_RAT2_SCALE * t2)
    )


@jax.custom_jvp
def _ellipse_shape(log_ratio):
    """(lambda, k, K(m), E(m)) of the contact with ln(R_x/R_y) = t: the root lambda = ln k of
    (1) and its elliptic integrals (one Newton step from `_initial_guess`, module docstring).
    Derivatives by the implicit-function theorem (custom JVP)."""
    t = jnp.asarray(log_ratio)
    lam0 = _initial_guess(t)
    _, b0, first, second, s, r = _elliptic_from_log_ellipticity(lam0)
    value = 2.0 * lam0 + jnp.log((1.0 - s) / s)
    d = (t - value) / _ratio_log_slope(s, r)
    # K and E carried to lambda_0 + d by their Taylor series to second order (module
    # docstring): dK = K [(1-S) d + ((1-S)^2 - S^2 + 2R) d^2/2], dE = K (1-m) [-S d + (S+2R) d^2/2]
    first_new = first * (1.0 + d * ((1.0 - s) + 0.5 * d * (jnp.square(1.0 - s) - s * s + 2.0 * r)))
    second_new = second + first * b0 * b0 * d * (-s + 0.5 * d * (s + 2.0 * r))
    k = (1.0 + d * (1.0 + 0.5 * d * (1.0 + d / 3.0))) / b0  # exp(lambda_0 + d), |d| < 4e-6
    return lam0 + d, k, first_new, second_new


@_ellipse_shape.defjvp
def _ellipse_shape_jvp(primals, tangents):
    # d lambda = dt / T'(lambda), dk = k d lambda; dK/dlambda = K (1 - S),
    # dE/dlambda = -K S (1 - m) (Legendre's dK/dm, dE/dm times dm/dlambda = 2 (1 - m)). The
    # primal outputs come from the function itself and the rest from differentiable AGM steps,
    # so higher derivatives are exact as well.
    (t,), (dt,) = primals, tangents
    out = _ellipse_shape(t)
    lam, k = out[0], out[1]
    m, _, first, _, s, r = _elliptic_from_log_ellipticity(lam)
    dlam = dt / _ratio_log_slope(s, r)
    return out, (dlam, k * dlam, first * (1.0 - s) * dlam, -first * s * (1.0 - m) * dlam)


def _saturated_log_ratio(radius_x, radius_y):
    """t = ln(R_x/R_y), hard-clipped at +-2L, then smoothly saturated at +-L (odd in t):
    t / (1 + (t/L)^32)^(1/32)."""
    t = jnp.log(jnp.asarray(radius_x)) - jnp.log(jnp.asarray(radius_y))
    t = jnp.clip(t, -2.0 * _LN_MAX_RATIO, 2.0 * _LN_MAX_RATIO)
    return t * jnp.exp(-jnp.log1p((t / _LN_MAX_RATIO) ** 32) / 32.0)  # integer power


def _exact(radius_x, radius_y):
    """Shared pieces: (R, lambda = ln k, k = a_x/a_y, K(m), E(m)) of the exact solution."""
    radius_x = jnp.asarray(radius_x)
    radius_y = jnp.asarray(radius_y)
    radius = 1.0 / (1.0 / radius_x + 1.0 / radius_y)
    lam, k, first, second = _ellipse_shape(_saturated_log_ratio(radius_x, radius_y))
    return radius, lam, k, first, second


def point_contact_ellipticity(
    radius_x: Float[ArrayLike, "*#batch"], radius_y: Float[ArrayLike, "*#batch"]
) -> Float[Array, "*batch"]:
    """Signed ellipticity a_x / a_y of the Hertz contact ellipse (independent of the load).

    The root k of R_x/R_y = (k^2 E(m) - K(m)) / (K(m) - E(m)), m = 1 - 1/k^2 (Johnson, Contact
    Mechanics, sec. 4.2), for either orientation: > 1 when R_x > R_y (the ellipse is long
    along x), 1 at R_x = R_y, and a_x/a_y(R_y, R_x) = 1 / (a_x/a_y)(R_x, R_y). C-infinity.
    Hamrock & Dowson's ellipticity parameter of an EHL contact rolling along x is a_y/a_x.
    """
    _, _, k, _, _ = _exact(radius_x, radius_y)
    return k


def point_contact_parameters(
    radius_x: Float[ArrayLike, "*#batch"], radius_y: Float[ArrayLike, "*#batch"]
) -> tuple[Float[Array, "*batch"], Float[Array, "*batch"], Float[Array, "*batch"]]:
    """(k, E(e), K(e)): exact ellipticity (long over short, >= 1) and elliptic integrals.

    The same quantities as `hamrock_brewe_parameters` (k = a/b, e^2 = 1 - 1/k^2), exact, for
    comparison with the fit and with tables. k has a kink at R_x = R_y by definition (it is
    |ln(a_x/a_y)| exponentiated); the contact functions do not use this form.
    """
    _, lam, k_x, first, second = _exact(radius_x, radius_y)
    # negative parameter back to the ordinary one: K(m') = k K(m), E(m') = E(m)/k, k = 1/k_x
    flip = lam < 0.0
    k = jnp.where(flip, 1.0 / k_x, k_x)
    return (
        k,
        jnp.where(flip, second * k_x, second),
        jnp.where(flip, first / k_x, first),
    )


# ------------------------------------------------------------------- Hamrock & Brewe fit
def _fit(radius_x, radius_y):
    """Hamrock-Brewe fit pieces: (k, Ecal, Fcal) with a smooth |ln(R_x/R_y)| (width 0.01)."""
    t = jnp.log(jnp.asarray(radius_x)) - jnp.log(jnp.asarray(radius_y))
    t = jnp.clip(t, -2 * _LN_MAX_RATIO, 2 * _LN_MAX_RATIO)
    ln_ratio = t * jnp.tanh(t / _RATIO_SMOOTHING)  # smooth |t|
    ln_ratio = _LN_MAX_RATIO - _SATURATION_WIDTH * jax.nn.softplus(
        (_LN_MAX_RATIO - ln_ratio) / _SATURATION_WIDTH
    )
    ellipticity = _K_COEF * jnp.exp(_K_EXP * ln_ratio)
    second_kind = _E_0 + _E_1 * jnp.exp(-ln_ratio)
    first_kind = _F_0 + _F_1 * ln_ratio
    return ellipticity, second_kind, first_kind


def hamrock_brewe_parameters(
    radius_x: Float[ArrayLike, "*#batch"], radius_y: Float[ArrayLike, "*#batch"]
) -> tuple[Float[Array, "*batch"], Float[Array, "*batch"], Float[Array, "*batch"]]:
    """(k, Ecal, Fcal) of the Hamrock & Brewe (1983) fit, for comparison with the exact law.

    k = 1.0339 alpha_r^0.6360, Ecal = 1.0003 + 0.5968/alpha_r, Fcal = 1.5277 + 0.6023 ln alpha_r,
    alpha_r = R_large/R_small (smoothed over a 1 % window at alpha_r = 1, saturated at
    `MAX_CURVATURE_RATIO`). "Simplified solution for stresses and deformations", J. Lubr.
    Technol. 105:171-177. Fitted over 1 <= alpha_r <= 100 (`HAMROCK_BREWE_ERROR`); the
    contact functions of this module no longer use it.
    """
    return _fit(radius_x, radius_y)


# ------------------------------------------------------------------------- contact laws
def point_contact_stiffness(
    radius_x: Float[ArrayLike, "*#batch"],
    radius_y: Float[ArrayLike, "*#batch"],
    e_prime: Float[ArrayLike, "*#batch"],
) -> Float[Array, "*batch"]:
    """Exact Hertz point-contact stiffness K_s with Q = K_s delta^(3/2) [N/m^1.5].

    K_s = pi k E' sqrt(E(m) R / (4.5 K(m)^3)), k = a_x/a_y from relation (1) of the module
    docstring, m = 1 - 1/k^2, R = 1/(1/R_x + 1/R_y) (Johnson, Contact Mechanics, sec. 4.2, in
    Hamrock & Brewe's 1983 notation; the paper's flange stiffness). Symmetric in
    R_x <-> R_y, C-infinity in both radii including R_x = R_y, finite for ratios up to and
    beyond `MAX_CURVATURE_RATIO` (saturated). Sphere on plane (R_x = R_y = r):
    K_s = (2/3) E' sqrt(r).

    Args:
        radius_x, radius_y: effective principal radii of curvature of the pair [m] (positive,
            convex; the caller sums the curvatures of both bodies per direction).
        e_prime: effective modulus E' [Pa] (`effective_modulus`).
    """
    radius, _, k, first, second = _exact(radius_x, radius_y)
    return jnp.pi * k * e_prime * jnp.sqrt(second * radius / (4.5 * first**3))


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
    """Semi-axes (a_x, a_y) of the exact Hertz contact ellipse along x and y [m].

    a_y = (6 E(m) Q R / (pi k E'))^(1/3), a_x = k a_y with the signed ellipticity k = a_x/a_y
    (`point_contact_ellipticity`): the long axis lies along the LARGER radius, and the ellipse
    turns smoothly through a circle when the radii cross (Johnson, Contact Mechanics, sec.
    4.2). Zero (with zero derivatives) for Q <= `LOAD_FLOOR`.
    """
    loaded, q = _safe_load(load)
    radius, _, k, _, second = _exact(radius_x, radius_y)
    a_y = jnp.cbrt(6.0 * second * q * radius / (jnp.pi * k * e_prime))
    return jnp.where(loaded, k * a_y, 0.0), jnp.where(loaded, a_y, 0.0)


def point_contact_peak_pressure(
    load: Float[ArrayLike, "*#batch"],
    radius_x: Float[ArrayLike, "*#batch"],
    radius_y: Float[ArrayLike, "*#batch"],
    e_prime: Float[ArrayLike, "*#batch"],
) -> Float[Array, "*batch"]:
    """Peak Hertz pressure p_max = 3 Q / (2 pi a_x a_y) [Pa], exact ellipse (the paper's p_max
    of the roller-flange contacts). Zero (with zero derivatives) for Q <= `LOAD_FLOOR`."""
    loaded, q = _safe_load(load)
    radius, _, k, _, second = _exact(radius_x, radius_y)
    a_y = jnp.cbrt(6.0 * second * q * radius / (jnp.pi * k * e_prime))
    return jnp.where(loaded, 3.0 * q / (2.0 * jnp.pi * k * a_y * a_y), 0.0)


def point_contact_deflection(
    load: Float[ArrayLike, "*#batch"],
    radius_x: Float[ArrayLike, "*#batch"],
    radius_y: Float[ArrayLike, "*#batch"],
    e_prime: Float[ArrayLike, "*#batch"],
) -> Float[Array, "*batch"]:
    """Elastic approach delta = (Q / K_s)^(2/3) [m], the inverse of `point_contact_stiffness`.

    Equal to K(m) (9/(2 E(m) R) (Q/(pi k E'))^2)^(1/3) = p_max a_y K(m) / E* (Johnson, Contact
    Mechanics, sec. 4.2). Zero (with zero derivatives) for Q <= `LOAD_FLOOR`.
    """
    loaded, q = _safe_load(load)
    stiffness = point_contact_stiffness(radius_x, radius_y, e_prime)
    return jnp.where(loaded, jnp.square(jnp.cbrt(q / stiffness)), 0.0)
