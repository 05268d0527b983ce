"""The sampled outputs of a solve are evaluated after the loop from the states it kept
(`jaxbearing.run._simulate._histories`): sample by sample they must be `_save` of those states,
whatever the number of samples against the chunk size (padding dropped, order kept)."""

import dataclasses

import jax
import jax.numpy as jnp
import numpy as np
import pytest

import jaxbearing as jb
from jaxbearing.dynamics import Params
from jaxbearing.run import Perturbation, prepare_from
from jaxbearing.run._initial import kinematic_start
from jaxbearing.run._simulate import HISTORY_CHUNK, _histories, _save, _saved_state


@pytest.fixture(scope="module")
def samples():
    """Args of a solve and 2 chunks + 3 scaled states near the start (random deviations)."""
    b, op = jb.reference_bearing(), jb.reference_operating_point()
    y0 = kinematic_start(b, op, Perturbation(seed=3))  # `initial_state`, compiled
    _, args, y0s, _ = prepare_from(Params(bearing=b, operating=op), y0, 1e-3, 1e-6)
    n = 2 * HISTORY_CHUNK + 3
    ts = jnp.linspace(0.0, 1e-4, n)
    rng = np.random.default_rng(0)
    states = jax.tree_util.tree_map(lambda a: a + 0.3 * rng.standard_normal((n, *np.shape(a))), y0s)
    return ts, states, args


def test_histories_are_the_outputs_of_each_kept_state(samples):
    ts, states, args = samples
    kept = jax.vmap(_saved_state, in_axes=(0, 0, None))(ts, states, args)
    assert kept.accumulators is None  # the solve keeps no integrals per sample
    hist = jax.jit(_histories)(ts, kept, args)
    one = jax.jit(_save)
    for i in (0, HISTORY_CHUNK - 1, HISTORY_CHUNK, len(ts) - 1):
        state = jax.tree_util.tree_map(lambda a: a[i], states)
        state = dataclasses.replace(
            state, accumulators=jax.tree_util.tree_map(jnp.zeros_like, state.accumulators)
        )
        expected = one(ts[i], state, args)
        assert set(hist) == set(expected)
        for key, value in expected.items():
            assert hist[key].shape == (len(ts), *np.shape(value)), key
            scale = float(np.max(np.abs(value)))  # atol: some outputs are differences near 0
            np.testing.assert_allclose(hist[key][i], value, rtol=1e-9, atol=1e-6 * scale, err_msg=key)
