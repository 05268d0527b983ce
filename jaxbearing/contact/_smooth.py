"""Smoothed contact primitives: penetration, Hertz-type power laws, norms and directions.

Every contact law of the model is written through these functions so that the vector field is
C1 in the state and finite in every derivative (docs/model.md section 7.3): diffrax evaluates the field
at unphysical states during step rejection, and forward/reverse-mode AD (including Hessians)
runs through it.

- Penetration is smoothed with a softplus of width eps: delta_s = eps softplus(delta / eps).
  It tends to delta for delta >> eps and to 0 for delta << -eps, with delta_s(0) = eps ln 2.
- Powers delta_s^n are evaluated in log space, n log(delta_s), so that underflow of delta_s far
  outside the contact gives an exact 0 with zero (not NaN) first and second derivatives.
- Norms use the double-`where` pattern (jax-md's `safe_mask`): the inner `where` keeps the
  argument of `sqrt` away from 0 so the untaken branch has a finite derivative.
- The friction direction is u / sqrt(|u|^2 + u_eps^2), which is smooth at u = 0.
"""

from __future__ import annotations

import jax
import jax.numpy as jnp
from jaxtyping import Array, ArrayLike, Float

#: Default softplus width of the penetration smoothing [m]. About a thousandth of the
#: interferences that carry load in a roller bearing (micrometres), so the smoothing changes
#: loaded contacts by less than 1e-3 relative while keeping the force law C-infinity.
PENETRATION_WIDTH = 1e-9

#: Default regularising speed of the sliding direction [m/s]. Below about this sliding speed the
#: friction force fades linearly to zero instead of switching sign (docs/model.md section 7.3).
SLIDING_EPS = 1e-3

# Below x = delta/eps = _LOG_SOFTPLUS_SWITCH, log(softplus(x)) is replaced by x: the relative
# error is exp(x)/2 < 1e-13 and the replacement has no underflow (softplus(-800) == 0).
_LOG_SOFTPLUS_SWITCH = -30.0


def smooth_penetration(
    delta: Float[ArrayLike, "*batch"], width: Float[ArrayLike, "*#batch"] = PENETRATION_WIDTH
) -> Float[Array, "*batch"]:
    """Softplus-smoothed penetration delta_s = eps ln(1 + exp(delta / eps)).

    Asymptotes: delta_s -> delta for delta >> eps (error eps exp(-delta/eps)), delta_s -> 0 for
    delta << -eps, delta_s(0) = eps ln 2. Derivatives d delta_s / d delta = sigmoid(delta/eps)
    in [0, 1] and d^2 delta_s / d delta^2 = sigmoid (1 - sigmoid) / eps are finite everywhere.
    Numerically safe for any |delta/eps| (`jax.nn.softplus`, i.e. log-add-exp).

    Args:
        delta: interference (positive = overlap) [m].
        width: softplus width eps > 0 [m], default `PENETRATION_WIDTH`.
    """
    delta = jnp.asarray(delta)
    return width * jax.nn.softplus(delta / width)


def log_smooth_penetration(
    delta: Float[ArrayLike, "*batch"], width: Float[ArrayLike, "*#batch"] = PENETRATION_WIDTH
) -> Float[Array, "*batch"]:
    """ln(delta_s) of `smooth_penetration`, finite for every delta (no log(0) on underflow).

    ln delta_s = ln eps + ln softplus(x), x = delta/eps; for x < -30, ln softplus(x) = x to a
    relative error below 1e-13 (softplus(x) = exp(x) (1 - exp(x)/2 + ...)). Double `where`
    keeps the untaken branch finite in value and derivatives.
    """
    x = jnp.asarray(delta) / width
    far = x < _LOG_SOFTPLUS_SWITCH
    x_safe = jnp.where(far, 0.0, x)
    return jnp.log(width) + jnp.where(far, x, jnp.log(jax.nn.softplus(x_safe)))


def smooth_power(
    delta: Float[ArrayLike, "*batch"],
    exponent: float | Float[ArrayLike, "*#batch"],
    width: Float[ArrayLike, "*#batch"] = PENETRATION_WIDTH,
) -> Float[Array, "*batch"]:
    """delta_s^n = exp(n ln delta_s): the smoothed power law of Hertz-type contacts.

    Written in log space so that far outside the contact (delta_s underflows to 0) the value
    and all derivatives are exactly 0 rather than 0 * inf = NaN, as `delta_s ** n` would give
    for the Hessian (n (n - 1) delta_s^(n-2) with delta_s = 0).
    """
    return jnp.exp(exponent * log_smooth_penetration(delta, width))


def hertz_force(
    delta: Float[ArrayLike, "*batch"],
    stiffness: Float[ArrayLike, "*#batch"],
    width: Float[ArrayLike, "*#batch"] = PENETRATION_WIDTH,
    exponent: float | Float[ArrayLike, "*#batch"] = 1.5,
) -> Float[Array, "*batch"]:
    """Smoothed Hertz-type contact force Q = K delta_s^n, delta_s = eps softplus(delta/eps).

    n = 3/2 for point contact (Hertz; Harris & Kotzalas, Essential Concepts of Bearing
    Technology, ch. 6; the paper's roller-flange law), n = 10/9 for line contact (Palmgren;
    ISO/TS 16281 lamina law). Monotone increasing in delta, C-infinity, with finite gradient and
    Hessian at, below and above zero penetration.

    Args:
        delta: interference [m] (positive = overlap).
        stiffness: K [N / m^n].
        width: softplus width eps [m].
        exponent: n.
    """
    return stiffness * smooth_power(delta, exponent, width)


def safe_norm(
    x: Float[ArrayLike, "*batch dim"],
    axis: int | tuple[int, ...] = -1,
    keepdims: bool = False,
    eps: float = 0.0,
) -> Float[Array, "*batch"]:
    """Euclidean norm |x| with finite gradient and Hessian at x = 0 (double-`where`).

    Where |x|^2 <= eps^2 the result is 0 with zero derivatives (the subgradient 0 is chosen at
    the kink); elsewhere it is the exact norm. With the default eps = 0 only the exact zero
    vector is masked. This is jax-md's `safe_mask` pattern: the inner `where` replaces the
    argument of `sqrt` by 1 on the masked branch, so its (discarded) derivative is finite and
    cannot poison the gradient with 0 * inf = NaN.
    """
    x = jnp.asarray(x)
    sq = jnp.sum(x * x, axis=axis, keepdims=keepdims)
    mask = sq > eps * eps
    return jnp.where(mask, jnp.sqrt(jnp.where(mask, sq, 1.0)), 0.0)


def smooth_direction(
    u: Float[ArrayLike, "*batch dim"], u_eps: Float[ArrayLike, "*#batch"] = SLIDING_EPS
) -> Float[Array, "*batch dim"]:
    """Regularised unit direction u / sqrt(|u|^2 + u_eps^2) along the last axis.

    The direction of a friction force (docs/model.md section 7.3): equal to u/|u| up to a relative
    error u_eps^2 / (2 |u|^2) for |u| >> u_eps, linear u/u_eps near u = 0, and C-infinity
    everywhere for u_eps > 0 (no division by |u|).
    """
    u = jnp.asarray(u)
    s = jnp.sqrt(jnp.sum(u * u, axis=-1, keepdims=True) + jnp.asarray(u_eps)[..., None] ** 2)
    return u / s
