"""A linearly implicit Rosenbrock-W solver with a per-roller block-diagonal Jacobian.

Why. The explicit solve (Tsit5) of the whole bearing is held by the roller's vibration between
its raceways (about 62 kHz, eigenvalue -5.6e4 +- 3.9e5 i at the reference point; unloaded
rollers about 2.5e5 i against the outer raceway under centrifugal load) and, behind it, by
roller tilt and azimuth modes (2.1e5-2.5e5). Every one of these modes lives in the
coordinates of *one* roller: a roller's forces depend on its own coordinates and on the
rings' and the cage's, never on another roller's. A linearly implicit method that treats the
per-roller block of the Jacobian implicitly and everything else explicitly is stable far
beyond the explicit limit without a dense 738 x 738 LU.

Method. ROS34PW2 of Rang & Angermann (2005, BIT 45:761, Table 4; the coefficients are those
of PETSc's `TSROSWRA34PW2`): four stages, order 3 with an embedded order-2 solution, L-stable,
stiffly accurate, and a *W-method*: its order conditions hold for any matrix T in place of the
Jacobian (Hairer & Wanner, Solving ODEs II, IV.7 "W-methods"), so T may be a cheap, stale or
partial approximation. One step from (t0, y0) with h = t1 - t0 (Hairer & Wanner IV.7 (7.4)):

    (I - gamma h T) k_i = h f(t0 + c_i h, y0 + sum_{j<i} alpha_ij k_j) + h T sum_{j<i} gamma_ij k_j,
    y1 = y0 + sum_i b_i k_i,          error estimate  sum_i (b_i - b^_i) k_i.

The problem is treated as autonomous in (y, t) with the t-column of T zero (the field's only
time dependence is the nominal orbit of the scaled state), which a W-method allows. f(t1, y1)
is the next step's first stage (FSAL), so a step attempt costs 4 field evaluations (stages 2-4
and f(t1, y1)) plus, when the block is refreshed, one batched JVP (`RollerBlockJacobian`).
Dense output between steps: cubic Hermite on (y0, y1, h f0, h f1), third order like the method.

T is `lax.stop_gradient`-ed: a W-method with any T is consistent, so derivatives carried
through the solve (forward or reverse mode) are those of the same scheme applied to the
variational equation, without second derivatives of the field.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import ClassVar

import diffrax
import equinox as eqx
import jax
import jax.numpy as jnp
import numpy as np
from jaxtyping import Array, Float

from .._errors import UserInputError

#: ROS34PW2 (Rang & Angermann 2005, Table 4): gamma, alpha_ij, gamma_ij (strictly lower),
#: b (order 3), b^ (embedded order 2).
ROS34PW2_GAMMA = 4.3586652150845900e-01
ROS34PW2_ALPHA = np.array(
    [
        [0.0, 0.0, 0.0, 0.0],
        [8.7173304301691801e-01, 0.0, 0.0, 0.0],
        [8.4457060015369423e-01, -1.1299064236484185e-01, 0.0, 0.0],
        [0.0, 0.0, 1.0, 0.0],
    ]
)
ROS34PW2_GAMMAS = np.array(
    [
        [0.0, 0.0, 0.0, 0.0],
        [-8.7173304301691801e-01, 0.0, 0.0, 0.0],
        [-9.0338057013044082e-01, 5.4180672388095326e-02, 0.0, 0.0],
        [2.4212380706095346e-01, -1.2232505839045147e00, 5.4526025533510214e-01, 0.0],
    ]
)
ROS34PW2_B = np.array(
    [2.4212380706095346e-01, -1.2232505839045147e00, 1.5452602553351020e00, 4.3586652150845900e-01]
)
ROS34PW2_B_EMBEDDED = np.array(
    [3.7810903145819369e-01, -9.6042292212423178e-02, 5.0000000000000000e-01, 2.1793326075422950e-01]
)


def _axpy(*terms):
    """sum_i c_i x_i over pytrees, skipping zero coefficients (terms: (c, x) pairs)."""
    terms = [(float(c), x) for c, x in terms if float(c) != 0.0]
    if not terms:
        raise ValueError("empty combination")
    c0, x0 = terms[0]
    out = jax.tree_util.tree_map(lambda a: c0 * a, x0)
    for c, x in terms[1:]:
        out = jax.tree_util.tree_map(lambda o, a, c=c: o + c * a, out, x)
    return out


class BlockJacobian(eqx.Module):
    """An approximation T of the Jacobian that can be applied and shifted-inverted:
    `matvec(v) = T v` and `shifted_solve(rhs, s) = (I - s T)^-1 rhs`."""

    def matvec(self, v):
        raise NotImplementedError

    def shifted_solve(self, rhs, s):
        raise NotImplementedError


class RosenbrockW(diffrax.AbstractAdaptiveSolver):
    """ROS34PW2 Rosenbrock-W solver (module docstring) for an `ODETerm`.

    `jacobian(f, t, y) -> BlockJacobian` builds T from the vector field `f(t, y)`;
    `refresh_every` (static): T is rebuilt at the start of every `refresh_every`-th accepted
    step (1: every step attempt) and kept in the solver state in between.
    """

    jacobian: Callable
    refresh_every: int = eqx.field(static=True, default=1)

    term_structure: ClassVar = diffrax.AbstractTerm
    interpolation_cls: ClassVar = diffrax.ThirdOrderHermitePolynomialInterpolation

    def order(self, terms):
        del terms
        return 3

    def _block(self, terms, t, y, args):
        block = self.jacobian(lambda t_, y_: terms.vf(t_, y_, args), t, y)
        return jax.lax.stop_gradient(block)

    def init(self, terms, t0, t1, y0, args):
        del t1
        f0 = terms.vf(t0, y0, args)
        return f0, self._block(terms, t0, y0, args), jnp.asarray(0, dtype=jnp.int32)

    def step(self, terms, t0, t1, y0, args, solver_state, made_jump):
        del made_jump
        f0, block, since = solver_state
        if self.refresh_every == 1:
            block = self._block(terms, t0, y0, args)
        else:
            block = jax.lax.cond(since == 0, lambda: self._block(terms, t0, y0, args), lambda: block)
        h = t1 - t0
        gh = ROS34PW2_GAMMA * h
        c = ROS34PW2_ALPHA.sum(axis=1)
        ks = []
        for i in range(4):
            if i == 0:
                fi = f0
            else:
                yi = _axpy((1.0, y0), *[(ROS34PW2_ALPHA[i, j], ks[j]) for j in range(i)])
                fi = terms.vf(t0 + c[i] * h, yi, args)
            rhs = jax.tree_util.tree_map(lambda a: h * a, fi)
            if i > 0 and np.any(ROS34PW2_GAMMAS[i, :i] != 0.0):
                tk = block.matvec(_axpy(*[(ROS34PW2_GAMMAS[i, j], ks[j]) for j in range(i)]))
                rhs = jax.tree_util.tree_map(lambda r, a: r + h * a, rhs, tk)
            ks.append(block.shifted_solve(rhs, gh))
        y1 = _axpy((1.0, y0), *[(ROS34PW2_B[i], ks[i]) for i in range(4)])
        y_error = _axpy(*[(ROS34PW2_B[i] - ROS34PW2_B_EMBEDDED[i], ks[i]) for i in range(4)])
        f1 = terms.vf(t1, y1, args)
        k0 = jax.tree_util.tree_map(lambda a: h * a, f0)
        k1 = jax.tree_util.tree_map(lambda a: h * a, f1)
        dense_info = dict(y0=y0, y1=y1, k0=k0, k1=k1)
        since = (since + 1) % self.refresh_every
        return y1, y_error, dense_info, (f1, block, since), diffrax.RESULTS.successful

    def func(self, terms, t0, y0, args):
        return terms.vf(t0, y0, args)


# -- dense-block approximations for tests and small systems -------------------------------------
class DenseBlock(BlockJacobian):
    """T as a dense matrix on a flat vector state (tests, small systems only)."""

    matrix: Float[Array, "n n"]

    def matvec(self, v):
        return self.matrix @ v

    def shifted_solve(self, rhs, s):
        return jnp.linalg.solve(jnp.eye(self.matrix.shape[0]) - s * self.matrix, rhs)


def dense_jacobian(f, t, y) -> DenseBlock:
    """The exact Jacobian of a flat-vector field as a `DenseBlock` (tests, small systems)."""
    return DenseBlock(matrix=jax.jacfwd(lambda y_: f(t, y_))(y))


# -- the bearing's per-roller block ------------------------------------------------------------
#: the roller coordinates of the implicit block, in order: every coordinate of a roller (12)
ROLLER_BLOCK_FIELDS = (
    "axial",
    "radial",
    "azimuth",
    "axis",
    "axial_velocity",
    "radial_velocity",
    "azimuth_rate",
    "angular_velocity",
)
#: the raceway-normal pair only (radial position and velocity, 2 per roller)
RADIAL_BLOCK_FIELDS = ("radial", "radial_velocity")


def _pack(rollers, fields) -> Array:
    """(Z, n) matrix of the block coordinates of every roller (fields in order, vectors
    component by component)."""
    cols = [jnp.reshape(getattr(rollers, name), (rollers.radial.shape[0], -1)) for name in fields]
    return jnp.concatenate(cols, axis=1)


def _unpack(u: Array, rollers, fields):
    """`rollers` with the block coordinates replaced by the columns of u (inverse of `_pack`)."""
    out, col = rollers, 0
    for name in fields:
        leaf = getattr(rollers, name)
        width = 1 if leaf.ndim == 1 else leaf.shape[1]
        value = jnp.reshape(u[:, col : col + width], leaf.shape)
        out = eqx.tree_at(lambda r, name=name: getattr(r, name), out, value)
        col += width
    return out


class RollerBlocks(BlockJacobian):
    """T = blockdiag over rollers of the (n x n) Jacobian of each roller's block coordinates
    (`fields`) with respect to its own block coordinates; zero in every other row and column,
    so (I - s T)^-1 is the identity outside the blocks. Acts on the scaled `State` pytree."""

    blocks: Float[Array, "Z n n"]
    fields: tuple = eqx.field(static=True)

    def matvec(self, v):
        u = jnp.einsum("zij,zj->zi", self.blocks, _pack(v.rollers, self.fields))
        zero = jax.tree_util.tree_map(jnp.zeros_like, v)
        return eqx.tree_at(lambda s: s.rollers, zero, _unpack(u, v.rollers, self.fields))

    def shifted_solve(self, rhs, s):
        n = self.blocks.shape[-1]
        w = jnp.eye(n) - s * self.blocks
        u = jnp.linalg.solve(w, _pack(rhs.rollers, self.fields)[..., None])[..., 0]
        return eqx.tree_at(lambda st: st.rollers, rhs, _unpack(u, rhs.rollers, self.fields))


class RollerBlockJacobian(eqx.Module):
    """Builds `RollerBlocks` with n JVPs (n = number of block coordinates per roller), each
    seeded on the same coordinate of *every* roller at once.

    A roller's rates depend on its own coordinates and on the rings' and the cage's, not on any
    other roller's (its contacts are with the raceways, flanges, cage pocket and the air), so
    the block rows of J v for a seed v = e_c on every roller are exactly each roller's own
    column c: d(rate of roller z)/d(coordinate c of roller z). n JVPs of the field (vmapped,
    primal computed once) give all Z blocks. `tests/test_rosenbrock.py` checks this against
    `jax.jacfwd`.
    """

    fields: tuple = eqx.field(static=True, default=ROLLER_BLOCK_FIELDS)

    def seeds(self, y):
        """(n, ...) batch of tangents: seed c is 1 on block coordinate c of every roller."""
        zero = jax.tree_util.tree_map(jnp.zeros_like, y)
        z, n = y.rollers.radial.shape[0], _pack(y.rollers, self.fields).shape[1]
        eye = jnp.broadcast_to(jnp.eye(n)[:, None, :], (n, z, n))

        def one(u):
            return eqx.tree_at(lambda s: s.rollers, zero, _unpack(u, zero.rollers, self.fields))

        return jax.vmap(one)(eye)

    def __call__(self, f, t, y) -> RollerBlocks:
        def tangent(v):
            return jax.jvp(lambda y_: f(t, y_), (y,), (v,))[1]

        cols = jax.vmap(tangent)(self.seeds(y))  # leaves (n, Z, ...): column c of every block
        packed = jax.vmap(lambda r: _pack(r, self.fields))(cols.rollers)  # (n cols, Z, n rows)
        return RollerBlocks(blocks=jnp.transpose(packed, (1, 2, 0)), fields=self.fields)


# -- the solvers `solve` offers ---------------------------------------------------------------
#: rebuild the per-roller blocks every this many accepted steps (ROS34PW2 keeps its order with
#: a stale T); 1, every step attempt, is what benchmarks/bench_work_precision.py --imex measured
JACOBIAN_REFRESH = 1
#: solver names accepted by `solve`, `simulate`, `simulate_steady`
SOLVERS = ("tsit5", "ros34pw2")
DEFAULT_SOLVER = "tsit5"


def check_solver(solver) -> None:
    """One-line `UserInputError` unless `solver` is one of `SOLVERS`."""
    if not isinstance(solver, str) or solver not in SOLVERS:
        raise UserInputError(f"solver = {solver!r}: must be one of {', '.join(map(repr, SOLVERS))}")


def diffrax_solver(name: str, refresh_every: int = JACOBIAN_REFRESH) -> diffrax.AbstractAdaptiveSolver:
    """The diffrax solver of a `solve`: "tsit5" (explicit, 5th order; the default) or
    "ros34pw2" (`RosenbrockW` with every roller's 12 x 12 block implicit)."""
    check_solver(name)
    if name == "ros34pw2":
        return RosenbrockW(jacobian=RollerBlockJacobian(), refresh_every=refresh_every)
    return diffrax.Tsit5()
