"""How many roller balances one static skid equilibrium costs, and a warm cage-speed bracket
tried in place of the full one (issue 37: the skid equilibrium of every fresh member):
``python benchmarks/studies/diagnose_skid_iterations.py [--warm-bracket | --illinois-rollers]``.

The reference bearing at 11 slices, 20,000 rpm, seeds 0-2: `run._initial._skid` compiled once,
then each seed timed warm, with every cage speed at which `dynamics._skid._roller_balance` runs
recorded (`jax.debug.callback`; each balance is 288 evaluations of the vector field). With
`--warm-bracket` the alternations' cage-speed search starts at the previous alternation's
speed +- 0.1 % and grows the bracket fourfold outward while both ends have one sign, instead of
searching `SPEED_BRACKET` every time. Finding (2026-11-26, 2-core CPU): full bracket 77-81
balances, 3.2-3.9 s warm, cage speed 893.92 rad/s; warm bracket 54-59 balances, 2.0-2.3 s, but
cage speed 951.21 rad/s: at the second alternation's cage centre the torque balance has roots
near 887 and 951 rad/s, and the warm bracket finds the far one (the dynamics' plateau is about
881 rad/s). Not adopted (docs/performance.md). Results: results/diagnose_skid_iterations[_warm].json.

With `--illinois-rollers` each roller's spin and pocket offset are found by the Illinois regula
falsi on the same brackets (every roller at once, one evaluation of the field per step, a
phase ending when every bracket is 2^-48 of its width, as the bisection's 48 steps leave it)
instead of by bisection, to see whether fewer evaluations of the field per roller balance
would do; the evaluations of each balance are recorded. Finding (2026-11-26, 2-core CPU): no
fewer than bisection's 288 (about 300 per balance: the offset's residual is flat inside the
pocket clearance, then stiff), no faster, and seed 0 ended on the bracket's end (973.89 rad/s,
the cage torque unbalanced). Not adopted. Results: results/diagnose_skid_iterations_illinois.json.
"""

from __future__ import annotations

import dataclasses
import sys
import time
from pathlib import Path

sys.path[:0] = [str(Path(__file__).resolve().parent), str(Path(__file__).resolve().parents[1])]
import _common  # noqa: E402

NAME = "diagnose_skid_iterations"
WARM_BRACKET = 1e-3  # half-width of the tried warm bracket, relative to the previous speed


def warm_cage_speed(original):
    """The tried variant of `dynamics._skid._cage_speed`: Illinois from a warm bracket that grows
    outward (module docstring); `original`'s module supplies the constants and the balance."""
    import jax
    import jax.numpy as jnp

    s = sys.modules[original.__module__]

    def cage_speed(params, base, centre, offset0, omega_kin, guess):
        z = base.rollers.azimuth.shape[0]
        lo, hi = s.SPEED_BRACKET[0] * omega_kin, s.SPEED_BRACKET[1] * omega_kin
        a0, b0 = jnp.clip(guess * (1 - WARM_BRACKET), lo, hi), jnp.clip(guess * (1 + WARM_BRACKET), lo, hi)

        def outward(a, b, fa, fb):
            return (fa * fb > 0) & (((fb > 0) & (b < hi)) | ((fa < 0) & (a > lo)))

        def cond(c):
            i, a, b, fa, fb = c[:5]
            open_ = (jnp.abs(b - a) > s._SPEED_RTOL * jnp.abs(omega_kin)) & (fa * fb < 0)
            return (i < 2) | ((i < s._SPEED_ITERATIONS) & (open_ | outward(a, b, fa, fb)))

        def body(c):
            i, a, b, fa, fb, side, _, _, _ = c
            grow = (i >= 2) & outward(a, b, fa, fb)
            above = fb > 0
            grown = jnp.where(above, jnp.minimum(hi, b + 4 * (b - a)), jnp.maximum(lo, a - 4 * (b - a)))
            regula = (a * fb - b * fa) / (fb - fa)
            inside = jnp.isfinite(regula) & (regula > jnp.minimum(a, b)) & (regula < jnp.maximum(a, b))
            step = jnp.where(grow, grown, jnp.where(inside, regula, 0.5 * (a + b)))
            m = jnp.where(i == 0, a, jnp.where(i == 1, b, step))
            spin, offset, fm, _ = s._roller_balance(params, base, m, centre, offset0)
            left = fm * fa > 0
            fb_kept = jnp.where(left & (side == 1), 0.5 * fb, fb)
            fa_kept = jnp.where(~left & (side == -1), 0.5 * fa, fa)
            a2, fa2 = jnp.where(left, m, a), jnp.where(left, fm, fa_kept)
            b2, fb2 = jnp.where(left, b, m), jnp.where(left, fb_kept, fm)
            side = jnp.where(grow, 0, jnp.where(i < 2, 0, jnp.where(left, 1, -1)))
            a2, fa2 = (
                jnp.where(grow, jnp.where(above, b, m), a2),
                jnp.where(grow, jnp.where(above, fb, fm), fa2),
            )
            b2, fb2 = (
                jnp.where(grow, jnp.where(above, m, a), b2),
                jnp.where(grow, jnp.where(above, fm, fa), fb2),
            )
            ends = i < 2
            a2, fa2 = jnp.where(ends, a, a2), jnp.where(i == 0, fm, jnp.where(ends, fa, fa2))
            b2, fb2 = jnp.where(ends, b, b2), jnp.where(i == 1, fm, jnp.where(ends, fb, fb2))
            return i + 1, a2, b2, fa2, fb2, side, m, spin, offset

        nan = jnp.asarray(jnp.nan)
        init = (0, a0, b0, nan, nan, 0, omega_kin, jnp.zeros(z), offset0)
        *_, m, spin, offset = jax.lax.while_loop(cond, body, init)
        return m, spin, offset

    return cage_speed


def illinois_roller_balance(skid, evaluations: list):
    """The tried variant of `dynamics._skid._roller_balance` (module docstring): Illinois instead
    of bisection in every phase of the block Gauss-Seidel rounds, one call site of the field;
    appends each balance's number of field evaluations to `evaluations`."""
    import jax
    import jax.numpy as jnp

    tol, cap = 2.0**-48, 64  # a phase ends at 2^-48 of its bracket, or after `cap` steps

    def balance(params, base, omega_c, centre, offset0):
        z = base.rollers.azimuth.shape[0]
        s_range, o_range = skid._balance_brackets(params, omega_c, z)  # the bisection's brackets

        def body(c):  # k = 0, 1: the bracket's ends; then Illinois steps
            p, k = c["phase"], c["k"]
            spin_phase = p % 2 == 0
            lo, hi, flo, fhi = c["lo"], c["hi"], c["flo"], c["fhi"]
            regula = (lo * fhi - hi * flo) / (fhi - flo)
            inside = jnp.isfinite(regula) & (regula > lo) & (regula < hi)
            x = jnp.where(k == 0, lo, jnp.where(k == 1, hi, jnp.where(inside, regula, 0.5 * (lo + hi))))
            spin = jnp.where(spin_phase, x, c["spin"])
            offset = jnp.where(spin_phase, c["offset"], x)
            spin_res, orbit_res, torque, force = skid._residuals(params, base, omega_c, spin, offset, centre)
            f = jnp.where(spin_phase, spin_res, orbit_res)
            flo, fhi = jnp.where(k == 0, f, flo), jnp.where(k == 1, f, fhi)
            at_lo = (k == 1) & (flo <= 0)  # a root outside the bracket pins it to that end
            at_hi = (k == 1) & (fhi >= 0) & ~at_lo
            lo, hi = jnp.where(at_hi, hi, lo), jnp.where(at_lo, lo, hi)
            step, up = k >= 2, f > 0  # decreasing residual: the root lies above x
            new_lo, new_hi = jnp.where(step & up, x, lo), jnp.where(step & ~up, x, hi)
            new_flo = jnp.where(step & up, f, jnp.where(step & ~up & (c["side"] == -1), 0.5 * flo, flo))
            new_fhi = jnp.where(step & ~up, f, jnp.where(step & up & (c["side"] == 1), 0.5 * fhi, fhi))
            exact = step & (f == 0)
            new_lo, new_hi = jnp.where(exact, x, new_lo), jnp.where(exact, x, new_hi)
            done = (k >= 1) & (jnp.all(new_hi - new_lo <= tol * (c["hi0"] - c["lo0"])) | (k >= cap + 1))
            value = 0.5 * (new_lo + new_hi)
            nxt = p + 1
            nlo = jnp.where(nxt % 2 == 0, s_range[0], o_range[0])
            nhi = jnp.where(nxt % 2 == 0, s_range[1], o_range[1])
            return dict(
                phase=jnp.where(done, nxt, p),
                k=jnp.where(done, 0, k + 1),
                lo=jnp.where(done, nlo, new_lo),
                hi=jnp.where(done, nhi, new_hi),
                lo0=jnp.where(done, nlo, c["lo0"]),
                hi0=jnp.where(done, nhi, c["hi0"]),
                flo=new_flo,
                fhi=new_fhi,
                side=jnp.where(done | ~step, 0, jnp.where(up, 1, -1)),
                spin=jnp.where(done & spin_phase, value, c["spin"]),
                offset=jnp.where(done & ~spin_phase, value, c["offset"]),
                torque=torque,
                force=force,
                evals=c["evals"] + 1,
            )

        init = dict(
            phase=jnp.asarray(0),
            k=jnp.asarray(0),
            lo=s_range[0],
            hi=s_range[1],
            lo0=s_range[0],
            hi0=s_range[1],
            flo=jnp.zeros(z),
            fhi=jnp.zeros(z),
            side=jnp.zeros(z, int),
            spin=jnp.zeros(z),
            offset=offset0,
            torque=jnp.zeros(()),
            force=jnp.zeros(2),
            evals=jnp.asarray(0),
        )
        out = jax.lax.while_loop(lambda c: c["phase"] < 2 * skid._GAUSS_SEIDEL_ROUNDS, body, init)
        jax.debug.callback(lambda e: evaluations.append(int(e)), out["evals"])
        return out["spin"], out["offset"], out["torque"], out["force"]

    return balance


def main(warm: bool = False, seeds: int = 3, illinois: bool = False) -> dict:
    import jax

    import jaxbearing as jb
    from jaxbearing.dynamics import _skid
    from jaxbearing.run import _initial

    speeds: list[float] = []
    evaluations: list[int] = []  # field evaluations per roller balance (--illinois-rollers)
    plain = (_skid._roller_balance, _skid._cage_speed, _skid._cage_centre)
    balance = illinois_roller_balance(_skid, evaluations) if illinois else plain[0]
    last_speed: list = [None]  # the alternation's speed, as `_cage_centre` receives it (traced)

    def counted(params, base, omega_c, centre, offset0):
        jax.debug.callback(lambda w: speeds.append(float(w)), omega_c)
        return balance(params, base, omega_c, centre, offset0)

    def centre_seen(params, base, omega_c, spin, offset, centre0):
        last_speed[0] = omega_c
        return plain[2](params, base, omega_c, spin, offset, centre0)

    _skid._roller_balance = counted
    if warm:  # each alternation searches from the speed it starts with (the kinematic one first)
        tried = warm_cage_speed(plain[1])
        _skid._cage_centre = centre_seen
        _skid._cage_speed = lambda p, b, c, o, w_kin: tried(p, b, c, o, w_kin, guess=last_speed[0])
    try:
        bearing = dataclasses.replace(jb.reference_bearing(), num_slices=11)
        op = jb.reference_operating_point()
        skid = jax.jit(_initial._skid)
        rows = []
        for seed in range(seeds):
            args = (bearing, op, _initial.traced_scatter(jb.Perturbation(seed=seed)))
            speeds.clear()
            evaluations.clear()
            t0 = time.perf_counter()
            out = jax.block_until_ready(skid(*args))
            rows.append(
                {
                    "seed": seed,
                    "seconds": time.perf_counter() - t0,  # the first includes compiling
                    "roller_balances": len(speeds),
                    "cage_speed_rad_s": float(out.equilibrium.cage_speed),
                    "balance_speeds_rad_s": list(speeds),
                    "cage_torque_residual_rad_s2": float(out.equilibrium.cage_torque_residual),
                    **({"field_evaluations_per_balance": list(evaluations)} if illinois else {}),
                }
            )
            _common.log(
                f"{NAME}: seed {seed}: {rows[-1]['seconds']:.2f} s, {len(speeds)} roller balances, "
                f"cage speed {rows[-1]['cage_speed_rad_s']:.4f} rad/s"
            )
    finally:
        _skid._roller_balance, _skid._cage_speed, _skid._cage_centre = plain
    data = {"warm_bracket": warm, "illinois_rollers": illinois, "num_slices": 11, "rows": rows}
    _common.write_json(NAME + ("_warm" if warm else "") + ("_illinois" if illinois else ""), data)
    return data


if __name__ == "__main__":
    main("--warm-bracket" in sys.argv, illinois="--illinois-rollers" in sys.argv)
