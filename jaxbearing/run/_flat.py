"""The explicit solve on one flat vector.

diffrax applies its stage sums, error estimate, interpolation and error norm leaf by leaf. The
scaled `State` has 22 leaves (the rollers' coordinates, the cage, the inner ring and the
accumulators of the smooth functionals), so each of those operations was 22 small programs per
stage. `flatten_problem` hands diffrax the state ravelled into one vector instead
(`jax.flatten_util.ravel_pytree`): one program per operation. The field, the error norm and
the saving functions see the `State` pytree again (`unravel`), so what they compute and what
the solve returns are unchanged; the stage sums act on the same numbers element by element.

Measured on the 2-core machine (`benchmarks/bench_work_precision_settled.py --reuse-reference
--tag flat --rows 26,28`, row 28 the pytree; docs/performance.md): wall time 1.00-1.05x, compile
0.85-0.96x, the same statistics.

Only explicit solvers take the flat vector: the Rosenbrock-W solver's Jacobian blocks are
built from the `State`'s roller coordinates (`_rosenbrock.RollerBlockJacobian`).
"""

from __future__ import annotations

from collections.abc import Callable

import diffrax
import equinox as eqx
import jax
from jax.flatten_util import ravel_pytree


def _on_pytree(fn: Callable, unravel: Callable) -> Callable:
    """fn(t, y, args) of a pytree state as a function of the flat vector."""
    return lambda t, y, args: fn(t, unravel(y), args)


def flatten_problem(field: Callable, y0, saveat: diffrax.SaveAt, controller: diffrax.PIDController):
    """(field, y0, saveat, controller) of the same problem on the flat vector of `y0`:

    * the field returns its rates ravelled as `y0` is (`field(t, unravel(y), args)`);
    * every `SubSaveAt`'s function receives the pytree, so `sol.ys` keeps its structure;
    * the controller's error norm receives the pytree of the scaled error.
    """
    flat0, unravel = ravel_pytree(y0)

    def flat_field(t, y, args):
        return ravel_pytree(field(t, unravel(y), args))[0]

    subs = jax.tree_util.tree_map(
        lambda sub: eqx.tree_at(lambda s: s.fn, sub, _on_pytree(sub.fn, unravel)),
        saveat.subs,
        is_leaf=lambda x: isinstance(x, diffrax.SubSaveAt),
    )
    flat_saveat = eqx.tree_at(lambda s: s.subs, saveat, subs)
    norm = controller.norm
    flat_controller = eqx.tree_at(lambda c: c.norm, controller, lambda y: norm(unravel(y)))
    return flat_field, flat0, flat_saveat, flat_controller
