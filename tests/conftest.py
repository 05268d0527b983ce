import jax

jax.config.update("jax_enable_x64", True)

#: test files slowest first. Seconds per file (the sum of its tests' setup, call and teardown)
#: in a cold-cache suite on the 2-core machine under load, 2026-11-25 (/tmp/junit_base.xml of the
#: coordinator's profile, 37 min wall, 805 tests): notebooks 589, steady_gradient 553, optimise
#: 482, sweep_distributed 408, dynamics 339, settle 276, skid 249, design 198, cmd_simulate 168,
#: quasistatic 132, program_cache 124, misalignment 103, rosenbrock 98, speed 94. Since then
#: (issue 37): notebook 05 also verifies (two more ensembles), test_settle's successful auto run
#: replaced the fixed-settle run (about twice its simulated time), test_cmd_simulate gained the
#: demo runs and test_dynamics' forced failure (the same program as its own failure run), so
#: settle and cmd_simulate move up. Cold, alone, 2026-11-26: steady_gradient 118 s (the
#: short-window forward mode and tangent growth are slow tests now; 223 s before), optimise
#: 139 s (162 s before), notebook 05 209 s, so steady_gradient moves below optimise and
#: sweep_distributed (not measured cold alone; about 170 s at the old profile's load ratio of
#: 2.4). `make test` runs `-n 2 --dist loadfile`: the two processes
#: take whole files in collection order, so the longest start first and the short files fill
#: in at the end (longest-processing-time-first scheduling). Unlisted files follow in their
#: usual order.
#: test_engine.py (issue 34: a settled sweep, vmapped members, a resumed batch, several
#: operating points; 11-slice settled runs). Cold, alone, 2026-11-26 (second measurement, the
#: other core busy): notebooks 276 s, engine 260 s, sweep_distributed 78-94 s (process 0 of
#: its two-process run loads the stored one-device batch program instead of compiling a
#: shard_map), skid 81 s, settle 78 s, misalignment 61 s, dynamics 59 s, cmd_simulate 59 s, sweep 48 s, design 43 s,
#: program_cache 31 s, quasistatic 21 s; so engine starts with the notebooks and
#: sweep_distributed follows steady_gradient. Cold, alone, 2026-11-26 (a third measurement, the
#: other core busy with a two-worker benchmark, load 3-5): skid 98 s, cmd_simulate 95 s, dynamics
#: 64-70 s, misalignment 52 s (113 s before its checks shared one compiled field), engine 217 s
#: (266 s before its continuing seeds' starts were compiled): misalignment moves below dynamics and
#: cmd_simulate above it.
SLOWEST_FILES_FIRST = (
    "test_notebooks.py",
    "test_engine.py",
    "test_optimise.py",
    "test_steady_gradient.py",
    "test_sweep_distributed.py",
    "test_skid.py",
    "test_settle.py",
    "test_cmd_simulate.py",
    "test_dynamics.py",
    "test_misalignment.py",
    "test_sweep.py",
    "test_design.py",
    "test_program_cache.py",
    "test_quasistatic.py",
    "test_rosenbrock.py",
    "test_speed.py",
)


def pytest_collection_modifyitems(config, items):
    rank = {name: i for i, name in enumerate(SLOWEST_FILES_FIRST)}
    items.sort(key=lambda item: rank.get(item.path.name, len(rank)))  # stable: order within a file kept
