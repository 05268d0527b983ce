"""How many Newton steps does the general end/rib contact need? Accuracy and cost of the
maximisation over a centre circle (`jaxbearing.flange._face_contact`, docs/model.md 5.4).

    python benchmarks/studies/study_face_newton.py [--samples 10000] [--tilt-mrad 10] [--rounds 15]

The solve runs `SCOUT_STEPS` Newton steps from each start angle, keeps the deepest end and runs
`NEWTON_STEPS` more from it. For each schedule (scout steps, refinement steps, starts) this
measures, over `--samples` faces and poses drawn as tests/test_faces.py draws them (e in
[0, 0.9 R_ce], kappa_rib in [0, 0.95 kappa_end], h_t in [0, H_rf], tilt and skew up to `--tilt-mrad`,
axial offsets of 20 um, all four flanges), the largest reported next step (`solve_error`) and
the largest differences in interference and contact point from 16 starts with 8 + 8 steps; and
the wall time of every flange contact of the reference bearing's 26 rollers (`all_flange_contacts`,
one jitted call, the part of the vector field the general faces change) for today's faces and
for a torus end (the design of benchmarks/results/optimise_profile_default_run.json) under each
schedule, timed round-robin in one process (best of `--rounds` rounds of 30 calls), so the ratios
are measured under the same load. The schedule is set through the module's constants before
each program is traced. Writes results/NAME.json (`--name`, default study_face_newton).
"""

from __future__ import annotations

import argparse
import math
import pathlib
import sys
import time

import numpy as np

HERE = pathlib.Path(__file__).resolve()
sys.path.insert(0, str(HERE.parents[1]))

import _common  # noqa: E402

#: (scout steps, refinement steps, starts); the first is the accuracy reference
SCHEDULES = ((8, 8, 16), (8, 8, 4), (3, 5, 4), (3, 5, 16), (2, 5, 4), (2, 5, 16), (3, 4, 4))
#: the schedules timed in the vector field's flange contacts (before and after)
TIMED = ((8, 8, 4), (3, 5, 4))


def _samples(bearing, n, seed, tilt_max):
    from jaxbearing.flange import roller_pose

    rng = np.random.default_rng(seed)
    r_ce = float(bearing.roller.diameter) / 2 - float(bearing.roller.corner_radius)
    k_end = 1 / float(bearing.roller.end_radius)
    rows = []
    for _ in range(n):
        off, conf, height = rng.uniform(0, 0.9), rng.uniform(0, 0.95), rng.uniform(0, 1)
        tilt, skew = rng.uniform(-tilt_max, tilt_max, 2)
        axial = rng.uniform(-20e-6, 20e-6)
        sign, side = rng.choice([1.0, -1.0]), rng.choice([1.0, -1.0])
        radius, p, axis = roller_pose(bearing, sign, axial, tilt, skew)
        rows.append(
            (off * r_ce, conf * k_end, height * float(bearing.flange.height), radius, side, sign, p, axis)
        )
    return [np.array(c) for c in zip(*rows)]


def _set(schedule):
    import jaxbearing.flange._face_contact as fcm

    fcm.SCOUT_STEPS, fcm.NEWTON_STEPS = schedule[0], schedule[1]


def _accuracy(bearing, cols):
    import jax
    import jax.numpy as jnp

    import jaxbearing.flange._face_contact as fcm
    from jaxbearing.flange import faces_of

    out = {}
    for schedule in SCHEDULES:
        _set(schedule)

        def one(e, k, h, r, s, g, p, a, starts=schedule[2]):
            faces = faces_of(bearing, end_offset=e, rib_curvature=k, rib_tangent_height=h)
            c = fcm.face_contact(bearing, faces, r, s, g, p, a, jnp.zeros(3), starts=starts)
            return c.interference, c.contact_point, c.solve_error

        out[schedule] = jax.jit(jax.vmap(one))(*cols)
    ref = out[SCHEDULES[0]]
    return [
        {
            "scout_steps": s[0],
            "newton_steps": s[1],
            "starts": s[2],
            "max_solve_error_m": float(np.max(o[2])),
            "max_interference_difference_m": float(np.max(np.abs(o[0] - ref[0]))),
            "max_contact_point_difference_m": float(np.max(np.abs(o[1] - ref[1]))),
        }
        for s, o in out.items()
    ]


def _cost(rounds):
    import jax
    import jax.numpy as jnp

    import jaxbearing as jb
    from jaxbearing.flange import ProfileVariables
    from jaxbearing.flange._contact import all_flange_contacts
    from jaxbearing.geometry import OperatingPoint
    from jaxbearing.run import Perturbation
    from jaxbearing.run._initial import initial_state

    bearing, ref_op = jb.reference_bearing(), jb.reference_operating_point()
    op = OperatingPoint(
        inner_speed=jb.rpm_to_rad_s(30000.0), radial_load=ref_op.radial_load, gravity=ref_op.gravity
    )
    torus = ProfileVariables(84.8e-3, 0.08e-3, 0.376e-3, 0.0, 0.0, np.deg2rad(1.68), 2.0e-3, 0.15e-3)
    state = initial_state(bearing, op, Perturbation(seed=1, axial=0.08e-3, skew=1e-3))
    r = state.rollers
    axis = r.axis / jnp.linalg.norm(r.axis, axis=-1, keepdims=True)
    zero = jnp.zeros(3)
    spin = jnp.array([float(op.inner_speed), 0.0, 0.0])
    args = (r.centre, axis, r.velocity, r.angular_velocity, zero, zero, spin, zero, zero, zero)
    programs = {"today's faces": (bearing, TIMED[0])}
    for schedule in TIMED:
        programs[f"torus end, {schedule[0]} + {schedule[1]} steps, {schedule[2]} starts"] = (
            torus.apply(bearing),
            schedule,
        )
    compiled = {}
    for name, (b, schedule) in programs.items():
        _set(schedule)
        f = jax.jit(lambda b, *a: all_flange_contacts(b, *a))  # a new function: traced afresh
        jax.block_until_ready(f(b, *args))
        compiled[name] = (f, b)
    best = dict.fromkeys(compiled, math.inf)
    for _ in range(rounds):
        for name, (f, b) in compiled.items():
            t = time.perf_counter()
            for _ in range(30):
                out = f(b, *args)
            jax.block_until_ready(out)
            best[name] = min(best[name], (time.perf_counter() - t) / 30)
    return {name: 1e6 * t for name, t in best.items()}


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--samples", type=int, default=10000)
    p.add_argument("--seed", type=int, default=0)
    p.add_argument("--rounds", type=int, default=15)
    p.add_argument("--name", default="study_face_newton", help="results/NAME.json")
    p.add_argument("--tilt-mrad", type=float, default=10.0, help="largest tilt and skew of the sampled poses")
    args = p.parse_args(argv)
    import jaxbearing as jb
    import jaxbearing.flange._face_contact as fcm

    kept = (fcm.SCOUT_STEPS, fcm.NEWTON_STEPS)
    bearing = jb.reference_bearing()
    accuracy = _accuracy(bearing, _samples(bearing, args.samples, args.seed, 1e-3 * args.tilt_mrad))
    cost = _cost(args.rounds)
    _set(kept)
    out = {
        "command": "python benchmarks/studies/study_face_newton.py "
        + " ".join(sys.argv[1:] if argv is None else argv),
        "samples": args.samples,
        "tilt_and_skew_max_mrad": args.tilt_mrad,
        "library_schedule": {"scout_steps": kept[0], "newton_steps": kept[1]},
        "accuracy": accuracy,
        "flange_contacts_us": cost,
        "machine": _common.machine_info(),
    }
    _common.write_json(args.name, out)
    for row in accuracy:
        print(row)
    for name, us in cost.items():
        print(f"{name}: {us:.0f} us")
    return 0


if __name__ == "__main__":
    sys.exit(main())
