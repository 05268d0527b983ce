"""Roller-raceway line contact: ISO/TS 16281 stiffness and the sliced load law (docs/model.md 8).

ISO/TS 16281:2008 (sec. 5.2, lamina model) gives the load-approach law of a cylindrical roller
between two steel raceways as Q = c_L delta_tot^(10/9), c_L = 35948 L_we^(8/9) (N, mm), with
delta_tot the TOTAL approach of both raceways, and cuts the roller into n_s laminae of stiffness
c_L / n_s.
One roller-raceway contact carries the same Q at half the approach, so its coefficient is

    k_c = 2^(10/9) 35948 L_we^(8/9)          [N/mm^(10/9), L_we in mm]
        = 2^(10/9) 35948e6 L_we^(8/9)        [N/m^(10/9), L_we in m]

(the unit change multiplies by 1000^(10/9) 1000^(8/9) = 1e6), and two contacts in series give
back ISO's total approach. Oracle: L_we = 10 mm, Q = 1000 N gives delta_tot = 6.308 um
(Palmgren's delta = 3.84e-5 Q^0.9 / l^0.8 mm per contact gives 6.100 um; Harris & Kotzalas,
Essential Concepts of Bearing Technology, ch. 6).

Material. The constant is for bearing steel. The steel behind these rolling-bearing constants
is E = 2.075e11 Pa (30e6 psi), nu = 0.3 (Harris & Kotzalas, ch. 6, who give Palmgren's
line-contact formula and the point-contact constant K = 2.15e5 (Sum rho)^(-1/2)
(delta*)^(-3/2) N/mm^1.5 for steel; that constant is the Hertz sphere-on-plane law with exactly
E* = E / (2 (1 - nu^2)) for this steel, which the tests check). ISO/TS 16281 states its constant
for bearing steel; its text was not available here, so the same steel is assumed
(E = 207-210 GPa would change k_c by at most 1.2 %). Other materials scale k_c by
E'/E'_steel (docs/model.md 8), E'_steel = E/(1 - nu^2) = `STEEL_E_PRIME`: the Hertz line-contact
approach at given load and length is proportional to 1/E', which the 10/9 law carries as k_c
proportional to E'.

Slices. docs/model.md 8: the effective length is cut into N_s slices; slice j carries
q_j = (k_c / N_s) delta_j^(10/9). Dividing the whole-contact coefficient by N_s (rather than
slicing the length inside the 8/9 power) keeps a uniformly loaded roller equal to the
whole-contact law, as ISO/TS 16281's lamina stiffness c_L / n_s does.
"""

from __future__ import annotations

import jax
import jax.numpy as jnp
from jaxtyping import Array, ArrayLike, Float

from ._smooth import _LOG_SOFTPLUS_SWITCH, PENETRATION_WIDTH

#: ISO/TS 16281 line-contact constant c_L = 35948 L_we^(8/9) [N, mm], total approach, steel.
ISO_LINE_CONSTANT = 35948.0

#: Exponent of the line-contact load-approach law Q = k delta^(10/9) (Palmgren; ISO/TS 16281).
LINE_EXPONENT = 10.0 / 9.0

#: Steel assumed by ISO/TS 16281 / Palmgren (Harris & Kotzalas): E [Pa] and Poisson's ratio.
STEEL_ELASTIC_MODULUS = 2.075e11
STEEL_POISSON_RATIO = 0.3
#: E' = E / (1 - nu^2) of steel on steel [Pa] (Hamrock's convention, `effective_modulus`).
STEEL_E_PRIME = STEEL_ELASTIC_MODULUS / (1.0 - STEEL_POISSON_RATIO**2)

# k_c [N/m^(10/9)] = _SI_PER_CONTACT * L_we[m]^(8/9) for steel
_SI_PER_CONTACT = 2.0 ** (10.0 / 9.0) * ISO_LINE_CONSTANT * 1e6


def _softplus_parts(delta, width):
    """(x, far, e, sp, log delta_s) of delta_s = eps softplus(x), x = delta/eps, sharing one
    exp: e = exp(-|x|), softplus(x) = max(x, 0) + log1p(e) (`smooth.log_smooth_penetration`;
    for x < -30, ln softplus(x) = x, double `where`)."""
    x = delta / width
    far = x < _LOG_SOFTPLUS_SWITCH
    x_safe = jnp.where(far, 0.0, x)
    e = jnp.exp(-jnp.abs(x_safe))
    sp = jnp.maximum(x_safe, 0.0) + jnp.log1p(e)
    log_ds = jnp.log(width) + jnp.where(far, x, jnp.log(sp))
    return x, far, x_safe, e, sp, log_ds


@jax.custom_jvp
def line_power(delta: Array, width: Array) -> Array:
    """delta_s^(10/9), delta_s = eps softplus(delta/eps): the line-contact power law in log space
    (`smooth.smooth_power` with n = 10/9, equal to it to rounding), with a hand-written tangent
    that reuses the primal's exp/log (a tangent costs about one primal evaluation):

        dP = (n P / eps) [r d(delta) + (1 - x r) d(eps)],  r = sigmoid(x) / softplus(x),

    (1 - x r evaluated without cancellation)

    from d delta_s/d delta = sigmoid(x), d delta_s/d eps = softplus(x) - x sigmoid(x); r -> 1
    far outside the contact (x < -30), where P = exp(n (ln eps + x)).
    """
    return jnp.exp(LINE_EXPONENT * _softplus_parts(delta, width)[-1])


@line_power.defjvp
def _line_power_jvp(primals, tangents):
    delta, width = primals
    d_delta, d_width = tangents
    x, far, x_safe, e, sp, log_ds = _softplus_parts(delta, width)
    p = jnp.exp(LINE_EXPONENT * log_ds)
    sigmoid = jnp.where(x_safe >= 0, 1.0, e) / (1.0 + e)
    r = jnp.where(far, 1.0, sigmoid / sp)
    # 1 - x r = (softplus - x sigmoid) / softplus = (log1p(e) + |x| e / (1 + e)) / softplus,
    # free of the cancellation of 1 - x r at large x
    width_factor = jnp.where(far, 1.0 - x, (jnp.log1p(e) + jnp.abs(x_safe) * e / (1.0 + e)) / sp)
    scale = LINE_EXPONENT * p / width
    return p, scale * (r * d_delta + width_factor * d_width)


def line_contact_stiffness(
    effective_length: Float[ArrayLike, "*#batch"],
    e_prime: Float[ArrayLike, "*#batch"] = STEEL_E_PRIME,
) -> Float[Array, "*batch"]:
    """Stiffness k_c of ONE roller-raceway line contact, Q = k_c delta^(10/9) [N/m^(10/9)].

    k_c = 2^(10/9) 35948 L_we^(8/9) (E'/E'_steel) in N, mm, converted to SI (ISO/TS 16281
    c_L per contact; docs/model.md 8). Two such contacts in series reproduce ISO's total approach.

    Args:
        effective_length: L_we [m] (the roller's `effective_length`, L_b1 - 2 R_cor).
        e_prime: effective modulus of the pair [Pa] (`effective_modulus`); default steel.
    """
    return (
        _SI_PER_CONTACT
        * jnp.asarray(effective_length) ** (8.0 / 9.0)
        * (jnp.asarray(e_prime) / STEEL_E_PRIME)
    )


def line_slice_loads(
    interference: Float[ArrayLike, "*batch slices"],
    contact_stiffness: Float[ArrayLike, "*#batch"],
    num_slices: int,
    width: Float[ArrayLike, "*#batch"] = PENETRATION_WIDTH,
) -> Float[Array, "*batch slices"]:
    """Loads of the N_s slices of one line contact: q_j = (k_c / N_s) delta_s,j^(10/9) [N].

    delta_s = eps softplus(delta/eps) (`smooth_penetration`), evaluated in log space so that
    unloaded slices give exactly 0 with finite derivatives (docs/model.md 8; ISO/TS 16281 sec. 5.2).

    Args:
        interference: slice interferences delta_j [m], last axis of length `num_slices`.
        contact_stiffness: k_c of the whole contact (`line_contact_stiffness`), broadcast over
            the leading axes.
        num_slices: N_s (static).
        width: softplus width eps [m].
    """
    interference = jnp.asarray(interference)
    if not isinstance(num_slices, int) or num_slices < 1:
        raise ValueError(f"num_slices must be a positive int, got {num_slices!r}")
    if interference.ndim == 0 or interference.shape[-1] != num_slices:
        raise ValueError(
            f"interference must have a last axis of length num_slices={num_slices}, "
            f"got shape {interference.shape}"
        )
    k_slice = jnp.asarray(contact_stiffness)[..., None] / num_slices
    width = jnp.broadcast_to(jnp.asarray(width, dtype=interference.dtype)[..., None], interference.shape)
    return k_slice * line_power(interference, width)
