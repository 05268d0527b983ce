"""Field evaluation speed against a baseline commit, measured in the same run (issue 12, item 3).

What it compares: the `jaxbearing` of `--current` (a git revision; default: this working tree)
against the one at `--baseline` (a git revision, default 92d850e). Revisions are checked out
into temporary git worktrees; each measurement runs in a fresh process with
`PYTHONPATH` pointing at one tree and the compilation caches off, and the processes alternate
(baseline, current, baseline, ...) `--repeats` times, so that the shared machine's load falls
on both alike. The minimum over the repeats is reported, and the ratio baseline / current.

Measured in each process, on the reference bearing at 20,000 rpm and 1000 N from the seeded
quasi-static start:

* ``field_us``: one evaluation of `physical_rates` inside a compiled `lax.fori_loop` of
  `EVALS` evaluations (no dispatch), wall / EVALS;
* ``tangents_us``: the same with three forward-mode tangents in the state and the design
  (R_end, theta_f, Delta_bf), as inside a `diffrax.ForwardMode` solve;
* ``solve_s_per_ms``: `jaxbearing.solve` (Tsit5, default tolerances, 2 saves) over `DURATION`,
  compile excluded, wall per simulated ms, with its step attempts (the two trees differ in
  rounding only, so their step counts agree to a few per cent);
* ``sampled_solve_compile_s`` and ``sampled_solve_s_per_ms``: the same solve with `SAMPLES`
  samples, the time from tracing to the compiled program (caches off) and the run's wall per
  simulated ms;
* ``flops``: XLA's operation count of the field and of the field with 3 tangents (independent
  of the load).

    python benchmarks/studies/bench_field_speed.py [--baseline REV] [--current REV] [--repeats N] [--quick]
        [--output NAME]

Measured (results/bench_field_speed.json): the raceway slices written by components, tuples of
(x, y, z) arrays over rollers x slices with the forces and moments summed by one stacked
reduction (commit 9de5eef, reverted by the next), against 92d850e: XLA counts 1.25x fewer flops
in the field and 1.46x fewer with three tangents, yet the field took 161.5 against 169.7 us
(1.05x), the field with three tangents 11,490 against 1,261 us (9.1x slower) and a solve 0.73
against 0.36 s per simulated ms (2.1x slower). The profile (`jax.profiler` with
XLA_FLAGS=--xla_cpu_enable_xprof_traceme=true) showed where: XLA fuses the per-slice producers
into each consumer of the stacked components, so a slice's contact law is evaluated once per
summed component; written with the pocket by components as well, one such fusion took 98 us of
a 240 us field.

Measured 2026-11-25, fourth session (`--baseline c695504 --current 0797e02 --repeats 3
--output bench_field_speed_one_raceway_vmap`, results/bench_field_speed_one_raceway_vmap.json;
0797e02 is an unlanded probe commit, its diff kept in git history (the commit that removed results/bench_field_speed_one_raceway_vmap.diff)): both raceways in one vmap over the rings, v_rel with one
cross product a slice ((v_b - v_r - w_r x (p - c_r)) + (w_b - w_r) x (x_j - p)) and the ring's
moment from the roller's (-(M_b + (p - c_r) x F)). XLA counts 1.62x fewer flops in the field
and 1.20x fewer with three tangents; the field took 311.7 against 336.3 us (1.08x), three
tangents 1.07x, the sampled solve 1.08x, but the plain solve 0.49-0.62 against 0.37-0.42 s per
simulated ms in all three pairs (0.76x). Not landed. (The machine ran the field at about 340 us
that day against 165-170 us in earlier sessions: shared and loaded.)

Measured 2026-11-25, fifth session (`--baseline HEAD --repeats 4 --output
bench_field_speed_slice_power`, results/bench_field_speed_slice_power.json; the working tree's
diff kept in git history (the commit that removed results/bench_field_speed_slice_power.diff)): the slice power `line_power` rewritten
exactly with cheaper float64 transcendentals, ln(1 + e) through `log` (Goldberg's ln(u) e/(u - 1))
and delta_s^(10/9) = delta_s exp(ln(delta_s)/9). Alone it took 11-13 against 19-22 ns a slice (a throwaway probe, not in the repository);
in the field it made XLA count 1.10x more flops, and the field took 370-387 against 347-360 us
in 4 alternating pairs (one baseline outlier at 260 us makes the minimum 0.70x), three tangents
1.00x, the plain solve 0.44-0.52 against 0.34-0.41 s per simulated ms (0.77x). Not landed.
`diagnose_field_bound.py` bounds what the contact laws can give at all.
"""

from __future__ import annotations

import argparse
import json
import os
import re
import subprocess
import sys
import tempfile
import time
from pathlib import Path

sys.path[:0] = [str(Path(__file__).resolve().parent), str(Path(__file__).resolve().parents[1])]

import _common  # noqa: E402

NAME = "bench_field_speed"
BASELINE = "92d850e"
EVALS = 400
DURATION = 0.5e-3  # [s]
SAMPLES = 500  # samples of the sampled solve (`sampled_solve_*`)
REPO = Path(__file__).resolve().parents[2]
#: the timings of a child process (the minimum over processes is reported)
TIMED = ("field_us", "tangents_us", "solve_s_per_ms", "sampled_solve_compile_s", "sampled_solve_s_per_ms")


def _loop_time(fn, repeats: int = 7) -> float:
    """min over `repeats` of the wall time of the compiled no-argument `fn`, per evaluation."""
    fn().block_until_ready()
    best = float("inf")
    for _ in range(repeats):
        t = time.perf_counter()
        fn().block_until_ready()
        best = min(best, time.perf_counter() - t)
    return best / EVALS


def reference_field() -> tuple:
    """(bearing, op, x0, y0, field, tangents, looped) of the module docstring, for the
    `jaxbearing` on `sys.path`: the reference bearing at its seeded quasi-static start, its
    design x0 = (R_end, theta_f, Delta_bf), `field(x, y)` (`physical_rates`), `tangents(x, y)`
    (the field with three forward-mode tangents in the state and the design, as inside a
    `diffrax.ForwardMode` solve) and `looped(fn)`: `EVALS` evaluations of `fn(x0, y)` in one
    jitted `lax.fori_loop` whose state depends on the carry (no dispatch, nothing hoisted).
    Also used by `diagnose_field_bound.py`."""
    import jax
    import jax.numpy as jnp

    import jaxbearing as jb
    from jaxbearing.dynamics import Params, physical_rates
    from jaxbearing.flange import DesignVariables

    bearing, op = jb.reference_bearing(), jb.reference_operating_point()
    y0 = jb.run.initial_state(bearing, op, jb.Perturbation(seed=0))
    x0 = DesignVariables.of(bearing).as_array()

    def field(x, y):
        b = DesignVariables.from_array(x).apply(bearing)
        return physical_rates(0.0, y, Params(bearing=b, operating=op))

    def tangents(x, y):
        basis = jnp.eye(3)
        ones = jax.tree_util.tree_map(lambda a: jnp.ones((3,) + a.shape), y)
        return jax.vmap(lambda d, t: jax.jvp(field, (x, y), (d, t)), out_axes=(None, 0))(basis, ones)

    def looped(fn):
        def body(i, acc):
            y = jax.tree_util.tree_map(lambda a: a + 1e-30 * acc, y0)
            out = fn(x0, y)
            return acc + 1e-30 * sum(jnp.sum(leaf) for leaf in jax.tree_util.tree_leaves(out))

        return jax.jit(lambda: jax.lax.fori_loop(0, EVALS, body, jnp.asarray(0.0)))

    return bearing, op, x0, y0, field, tangents, looped


def child() -> dict:
    """The measurements of the module docstring for the `jaxbearing` on `sys.path`."""
    import jax

    import jaxbearing as jb

    bearing, op, x0, y0, field, tangents, looped = reference_field()

    def flops(fn):
        cost = jax.jit(fn).lower(x0, y0).compile().cost_analysis()
        return float((cost[0] if isinstance(cost, list) else cost)["flops"])

    def timed_solve(num_saves: int):
        """(compile s, trace to compiled program; min run wall of 3; the solution)"""
        t = time.perf_counter()
        compiled = (
            jax.jit(
                lambda b: jb.run.solve(
                    b, op, DURATION, num_saves=num_saves, perturbation=jb.Perturbation(seed=0)
                )
            )
            .lower(bearing)
            .compile()
        )
        compile_s = time.perf_counter() - t
        jax.block_until_ready(compiled(bearing))
        walls = []
        for _ in range(3):
            t = time.perf_counter()
            sol = compiled(bearing)
            jax.block_until_ready(sol)
            walls.append(time.perf_counter() - t)
        return compile_s, min(walls), sol

    _, wall, sol = timed_solve(2)
    sampled_compile_s, sampled_wall, _ = timed_solve(SAMPLES)
    return {
        "field_us": 1e6 * _loop_time(looped(field)),
        "tangents_us": 1e6 * _loop_time(looped(tangents)),
        "solve_s_per_ms": wall / (DURATION * 1e3),
        "sampled_solve_compile_s": sampled_compile_s,
        "sampled_solve_s_per_ms": sampled_wall / (DURATION * 1e3),
        "solve_step_attempts": int(sol.num_steps),
        "solve_ok": int(sol.result) == 0,
        "field_flops": flops(field),
        "tangents_flops": flops(tangents),
    }


def _run_child(tree: Path) -> dict:
    env = dict(os.environ, PYTHONPATH=str(tree), JAXBEARING_CACHE_DIR="off")
    out = subprocess.run(
        [sys.executable, __file__, "--child"], env=env, cwd=tree, capture_output=True, text=True, check=False
    )
    if out.returncode != 0:
        raise RuntimeError(f"{NAME}: the measurement in {tree} failed:\n{out.stderr[-3000:]}")
    return json.loads(out.stdout.strip().splitlines()[-1])


class UsageError(ValueError):
    """An argument of `main` out of range (the command line prints it as a usage error)."""


def check_arguments(baseline: str, current: str | None, repeats: int, output: str = NAME) -> None:
    """UsageError naming the argument unless `repeats` >= 1, `output` is a plain file name
    (letters, digits, '_', '-') and git resolves `baseline` and `current` (when given) to
    commits of this repository."""
    if repeats < 1:
        raise UsageError(f"--repeats = {repeats}: must be at least 1")
    if not re.fullmatch(r"[A-Za-z0-9_-]+", output):
        raise UsageError(f"--output = {output!r}: must be a file name of letters, digits, '_' and '-'")
    for name, rev in (("--baseline", baseline), ("--current", current)):
        if rev is None:
            continue
        out = subprocess.run(
            ["git", "-C", str(REPO), "rev-parse", "--verify", "--quiet", f"{rev}^{{commit}}"],
            capture_output=True,
            check=False,
        )
        if out.returncode != 0:
            raise UsageError(f"{name} = {rev!r}: not a commit of {REPO} (git rev-parse --verify failed)")


def main(
    quick: bool = False,
    baseline: str = BASELINE,
    current: str | None = None,
    repeats: int = 3,
    output: str = NAME,
) -> dict:
    """Measure, print the table, write `results/<output>.json` (module docstring)."""
    repeats = 1 if quick else repeats
    check_arguments(baseline, current, repeats, output)
    runs: dict[str, list[dict]] = {"baseline": [], "current": []}
    revisions = {"baseline": baseline, "current": current}
    with tempfile.TemporaryDirectory() as tmp:
        trees = {w: REPO if rev is None else Path(tmp) / w for w, rev in revisions.items()}
        added = []
        try:
            for which, rev in revisions.items():
                if rev is not None:
                    subprocess.run(
                        ["git", "-C", str(REPO), "worktree", "add", "--detach", "-q", str(trees[which]), rev],
                        check=True,
                    )
                    added.append(trees[which])
            for i in range(repeats):
                for which, path in trees.items():
                    _common.log(f"{NAME}: {which}, repeat {i + 1} of {repeats}")
                    runs[which].append(_run_child(path))
        finally:
            for tree in added:
                subprocess.run(
                    ["git", "-C", str(REPO), "worktree", "remove", "--force", str(tree)], check=False
                )
    best = {w: {k: min(r[k] for r in rs) for k in TIMED} for w, rs in runs.items()}
    for w, rs in runs.items():
        best[w].update(
            {k: rs[0][k] for k in ("field_flops", "tangents_flops", "solve_step_attempts", "solve_ok")}
        )
    ratios = {k: best["baseline"][k] / best["current"][k] for k in (*TIMED, "field_flops", "tangents_flops")}
    for w in best:
        best[w]["tangents_vs_field"] = best[w]["tangents_us"] / best[w]["field_us"]
    result = {
        "benchmark": NAME,
        "baseline": baseline,
        "current": current or "working tree",
        "case": "reference bearing, 20,000 rpm, 1000 N; seeded quasi-static start",
        "repeats": repeats,
        "best": best,
        "baseline_over_current": ratios,
        "runs": runs,
        "machine": _common.machine_info(),
    }
    rows = [
        [k, best["baseline"][k], best["current"][k], ratios[k]]
        for k in (*TIMED, "field_flops", "tangents_flops")
    ]
    rows.append(
        [
            "field + 3 tangents / field",
            best["baseline"]["tangents_vs_field"],
            best["current"]["tangents_vs_field"],
            "",
        ]
    )
    rows.append(
        [
            "solve step attempts",
            best["baseline"]["solve_step_attempts"],
            best["current"]["solve_step_attempts"],
            "",
        ]
    )
    result["table"] = _common.format_table(
        f"Field speed, {current or 'this tree'} against {baseline} (min of {repeats} alternating processes)",
        ["quantity", "baseline", "current", "baseline / current"],
        rows,
    )
    print(result["table"])
    _common.write_json(output, result)
    return result


if __name__ == "__main__":
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--baseline", default=BASELINE, help="git revision to compare against")
    parser.add_argument(
        "--current", default=None, help="git revision to measure (default: this working tree)"
    )
    parser.add_argument("--repeats", type=int, default=3, help="alternating processes per tree")
    parser.add_argument("--quick", action="store_true", help="one process per tree")
    parser.add_argument(
        "--output", default=NAME, help=f"results file name in benchmarks/results (default {NAME})"
    )
    parser.add_argument("--child", action="store_true", help=argparse.SUPPRESS)
    a = parser.parse_args()
    if a.child:
        print(json.dumps(child()))
    else:
        try:
            main(a.quick, a.baseline, a.current, a.repeats, a.output)
        except UsageError as err:
            parser.error(str(err))
