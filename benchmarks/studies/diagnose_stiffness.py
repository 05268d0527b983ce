"""Why the Rosenbrock-W solver does not beat Tsit5 (issue 12, item 2): where the step of the
reference bearing's solve is held. Not a `bench_*` (not in `make bench`); a few minutes.

1. The dense Jacobian (diagnosis only) of the scaled field at t = 1.5 ms of a Tsit5 run
   (rtol 1e-4, seed 0): its largest eigenvalues, the state component each mode lives in, and
   Tsit5's stability limit for each (`bench_work_precision.tsit5_stability_limit`).
2. The spectral radius of ROS34PW2's amplification matrix on the linearised field, with T the
   per-roller blocks of (a) nothing, (b) the radial pair, (c) radial + axis + angular velocity,
   (d) all 12 roller coordinates, against the step h: up to which h the W-method is stable.
3. The error estimate of one step from that state, per state leaf, in units of the tolerance
   (rtol 1e-3, atol 1e-6, raceway-normal weights 1/100), for Tsit5 and ROS34PW2 at h = 1-8 us:
   which coordinates hold the step.
Writes benchmarks/results/diagnose_stiffness.json.
"""

from __future__ import annotations

import sys
import time
from pathlib import Path

sys.path[:0] = [str(Path(__file__).resolve().parent), str(Path(__file__).resolve().parents[1])]

import _common  # noqa: E402

NAME = "diagnose_stiffness"


def main() -> dict:
    import diffrax
    import jax
    import jax.numpy as jnp
    import numpy as np
    from bench_work_precision import tsit5_stability_limit

    import jaxbearing as jb
    from jaxbearing.run import _rosenbrock as ros
    from jaxbearing.run import scaled_field
    from jaxbearing.run._step_control import raceway_normal_weights

    started = time.perf_counter()
    b, op = jb.reference_bearing(), jb.reference_operating_point()
    ff = _common.FlatField(b, op, perturbation=jb.Perturbation(seed=0))
    t1 = 1.5e-3
    term = diffrax.ODETerm(lambda t, y, a: ff(t, y, a))
    sol = jax.jit(
        lambda y0, a: diffrax.diffeqsolve(
            term,
            diffrax.Tsit5(),
            0.0,
            t1,
            1e-7,
            y0,
            args=a,
            stepsize_controller=diffrax.PIDController(rtol=1e-4, atol=1e-6, pcoeff=0.3, icoeff=0.4),
            max_steps=100_000,
        )
    )(ff.y0, ff.args_flat)
    y_flat = sol.ys[-1]
    jac = np.asarray(jax.jit(jax.jacfwd(lambda y: ff(t1, y, ff.args_flat)))(y_flat))
    state = ff._unravel_state(y_flat)
    names, rollers = [], []
    for path, leaf in jax.tree_util.tree_flatten_with_path(state)[0]:
        name = jax.tree_util.keystr(path)
        for idx in np.ndindex(np.shape(leaf)):
            names.append(name)
            rollers.append(idx[0] if name.startswith(".rollers") else -1)
    names, rollers = np.array(names), np.array(rollers)

    # 1. eigenvalues
    w, v = np.linalg.eig(jac)
    order = np.argsort(-np.abs(w))
    modes = []
    for k in order[:60:2]:  # conjugate pairs: every other
        top = int(np.argmax(np.abs(v[:, k])))
        modes.append(
            {
                "eigenvalue": [float(w[k].real), float(w[k].imag)],
                "component": f"{names[top]}[roller {rollers[top]}]",
                "tsit5_limit_us": 1e6 * tsit5_stability_limit(complex(w[k]), 1e-4),
            }
        )

    # 2. spectral radius of the W-method's amplification matrix
    n = len(jac)
    alpha, gammas, bw, g = ros.ROS34PW2_ALPHA, ros.ROS34PW2_GAMMAS, ros.ROS34PW2_B, ros.ROS34PW2_GAMMA

    def block_of(fields):
        t = np.zeros_like(jac)
        inside = np.isin(names, [f".rollers.{f}" for f in fields])
        for r in range(b.num_rollers):
            idx = np.flatnonzero(inside & (rollers == r))
            t[np.ix_(idx, idx)] = jac[np.ix_(idx, idx)]
        return t

    def radius(h, t):
        wi = np.linalg.inv(np.eye(n) - g * h * t)
        ks = []
        for i in range(4):
            yi = np.eye(n) + sum((alpha[i, j] * ks[j] for j in range(i)), np.zeros((n, n)))
            rhs = h * jac @ yi + h * t @ sum((gammas[i, j] * ks[j] for j in range(i)), np.zeros((n, n)))
            ks.append(wi @ rhs)
        amp = np.eye(n) + sum(bw[i] * ks[i] for i in range(4))
        return float(np.max(np.abs(np.linalg.eigvals(amp))))

    blocks = {
        "none (explicit)": (),
        "radial pair": ros.RADIAL_BLOCK_FIELDS,
        "radial + axis + angular velocity": ("radial", "radial_velocity", "axis", "angular_velocity"),
        "all 12 roller coordinates": ros.ROLLER_BLOCK_FIELDS,
    }
    hs = [2e-6, 4e-6, 6e-6, 8e-6, 10e-6, 15e-6, 20e-6, 30e-6, 50e-6]
    radii = {name: {f"{h * 1e6:g} us": radius(h, block_of(f)) for h in hs} for name, f in blocks.items()}

    # 3. one step's error estimate per leaf
    y = state
    weights = raceway_normal_weights(y, 100.0)
    fterm = diffrax.ODETerm(scaled_field)

    def scaled_errors(solver, h):
        st = solver.init(fterm, t1, t1 + h, y, ff.args)
        y1, err, *_ = solver.step(fterm, t1, t1 + h, y, ff.args, st, False)
        return jax.tree_util.tree_map(
            lambda e, a, c, wt: wt * jnp.abs(e) / (1e-6 + 1e-3 * jnp.maximum(jnp.abs(a), jnp.abs(c))),
            err,
            y,
            y1,
            weights,
        )

    errors = {}
    for label, solver in (("tsit5", diffrax.Tsit5()), ("ros34pw2", ros.diffrax_solver("ros34pw2"))):
        f = jax.jit(lambda h, solver=solver: scaled_errors(solver, h))
        errors[label] = {}
        for h in (1e-6, 2e-6, 4e-6, 8e-6):
            leaves = jax.tree_util.tree_flatten_with_path(f(h))[0]
            per_leaf = sorted(
                ((jax.tree_util.keystr(p), float(jnp.max(x))) for p, x in leaves), key=lambda x: -x[1]
            )
            errors[label][f"{h * 1e6:g} us"] = dict(per_leaf[:4])

    result = {
        "benchmark": NAME,
        "state": "reference bearing, 20,000 rpm, 1000 N, seed 0, t = 1.5 ms of Tsit5 (rtol 1e-4)",
        "largest_modes": modes,
        "w_method_spectral_radius": radii,
        "step_error_in_tolerances": errors,
        "wall_s": time.perf_counter() - started,
    }
    _common.write_json(NAME, result)
    for name, r in radii.items():
        print(name, {k: round(x, 3) for k, x in r.items()})
    for label, e in errors.items():
        for h, leaves in e.items():
            print(label, h, {k: f"{x:.3g}" for k, x in leaves.items()})
    return result


if __name__ == "__main__":
    main()
