"""The profile search (eight variables of the roller end and rib faces): its box, problem,
command line and face drawing, without dynamics (the dynamics of the faces:
tests/test_faces_dynamics.py; their gradients: tests/test_profile_gradients.py).

Checked: the three-variable box is unchanged (its bounds are the same numbers); `ProfileBounds`
rejects every box some corner of which makes no faces of the roller, in one line; the problem
maps the unit box onto `ProfileVariables`, its margins and their Jacobian have eight columns,
and a feasible start exists; the command line and the TOML file select the profile search and
hand their bounds to the problem; the drawn meridians agree with closed forms."""

import math

import jax
import jax.numpy as jnp
import numpy as np
import pytest

import optimise as opt
import optimise._cli as cli
import optimise._evaluate as evaluation
from jaxbearing import UserInputError, reference_bearing, reference_operating_point
from jaxbearing.flange import PROFILE_NAMES, DesignVariables, ProfileVariables, face_protrusion, faces_of
from optimise._bounds import PROFILE_TABLE, ProfileBounds, box_from_engineering
from optimise._faces_plot import face_meridians, plot_faces
from optimise._search import start_points

MM, DEG = 1e-3, math.pi / 180
BEARING = reference_bearing()
OP = reference_operating_point()


def test_three_variable_bounds_are_the_same_numbers():
    b = opt.bounds_from_engineering([60, 120], [1.0, 2.0], [0.1, 0.3])
    assert b == opt.Bounds()
    np.testing.assert_array_equal(b.lower, [60 * 1e-3, 1.0 * (math.pi / 180), 0.10 * 1e-3])
    np.testing.assert_array_equal(b.upper, [120 * 1e-3, 2.0 * (math.pi / 180), 0.30 * 1e-3])
    assert b.clearance_index == 2 and b.names == ("end_radius", "layback_angle", "axial_clearance")


def test_profile_box_follows_the_profile_order():
    b = ProfileBounds()
    assert b.names == PROFILE_NAMES and b.clearance_index == 7
    b.check(BEARING)
    assert set(b.engineering()) == {v.key for v in PROFILE_TABLE}


@pytest.mark.parametrize(
    "values,text",
    [
        ({"end_offset_mm": [0.0, 3.2]}, "bounds.end_offset_mm upper bound = 3.2: must be < D/2 - R_cor"),
        (
            {"rib_curvature_per_m": [0.0, 9.0]},
            "bounds.rib_curvature_per_m upper bound = 9.0: must be < 1/R_end",
        ),
        (
            {"flange_height_mm": [1.7, 2.4]},
            "bounds.flange_height_mm lower bound = 1.7: must be > the contact",
        ),
        ({"flange_height_mm": [1.9, 8.0]}, "bounds.flange_height_mm upper bound = 8.0: must be < D = 7.5 mm"),
        ({"corner_radius_mm": [0.3, 4.0]}, "bounds.corner_radius_mm upper bound = 4.0: must be < D/2"),
        (
            {"rib_tangent_height_mm": [0.0, 2.0]},
            "bounds.rib_tangent_height_mm upper bound = 2.0: must be <= H_rf",
        ),
        ({"end_radius_mm": [3.0, 120.0]}, "bounds.end_radius_mm lower bound = 3.0: must be > D/2"),
    ],
)
def test_profile_boxes_without_faces_are_one_line(values, text):
    with pytest.raises(UserInputError, match=text.replace("(", r"\(")) as info:
        opt.make_problem(BEARING, OP, bounds=box_from_engineering(ProfileBounds, values))
    assert "\n" not in str(info.value)


@pytest.mark.parametrize(
    "values,text",
    [
        ({"end_offset_mm": [-0.1, 1.0]}, "bounds.end_offset_mm lower bound = -0.1: must be >= 0 mm"),
        ({"corner_radius_mm": [0.5, 0.4]}, "bounds.corner_radius_mm = [0.5, 0.4]: lower bound above upper"),
        ({"rib_curvature_per_m": [0.0, float("nan")]}, "bounds.rib_curvature_per_m upper bound = nan"),
        ({"flange_height_mm": [2.0]}, "bounds.flange_height_mm: expected [lower, upper]"),
        ({"end_offset": [0.0, 1.0]}, "bounds.end_offset: unknown"),
    ],
)
def test_bad_profile_bounds_are_one_line(values, text):
    with pytest.raises(UserInputError, match=text.replace("(", r"\(").replace("[", r"\[")):
        box_from_engineering(ProfileBounds, values)


def test_the_problem_maps_the_box_onto_profiles():
    problem = opt.make_problem(BEARING, OP, bounds=ProfileBounds())
    assert problem.num_variables == 8
    u = jnp.full(8, 0.5)
    design = problem.design(u)
    assert isinstance(design, ProfileVariables)
    np.testing.assert_allclose(design.as_array(), (problem.bounds.lower + problem.bounds.upper) / 2)
    jac = np.asarray(jax.jacfwd(problem.constraints)(u))
    assert jac.shape == (4, 8) and np.all(np.isfinite(jac))
    # the flange height and h_t on a cone move no static margin
    assert np.all(jac[:, PROFILE_NAMES.index("flange_height")] == 0)
    found, best = opt.any_feasible(problem, n=8)
    assert found and best.shape == (8,)


def test_starts_begin_at_the_bearing_s_own_profile():
    problem = opt.make_problem(BEARING, OP, bounds=ProfileBounds())
    u = start_points(problem, 3)
    assert u.shape == (3, 8) and np.all((u >= 0) & (u <= 1))
    own = ProfileVariables.of(BEARING).as_array()
    np.testing.assert_allclose(problem.bounds.from_scaled(u[0]), own, rtol=1e-12, atol=1e-15)
    assert len({tuple(row) for row in u}) == 3


def test_the_clearance_shift_moves_delta_bf_only():
    profile = ProfileVariables.of(BEARING)
    shifted = evaluation._shift_clearance(profile, 1e-5, 7)
    delta = np.asarray(shifted.as_array() - profile.as_array())
    np.testing.assert_allclose(delta, [0, 0, 0, 0, 0, 0, 0, 1e-5], atol=1e-18)
    three = evaluation._shift_clearance(DesignVariables.of(BEARING), 1e-5, 2)
    assert isinstance(three, DesignVariables)


def test_profile_search_needs_the_steady_frozen_search():
    problem = opt.make_problem(BEARING, OP, bounds=ProfileBounds())
    with pytest.raises(UserInputError, match="needs the frozen-load estimator"):
        opt.steady_search(problem, opt.SteadySettings(estimator="window"), num_starts=1, num_iterations=1)
    with pytest.raises(UserInputError, match="start-up objective searches R_end"):
        problem.peak_pv(jnp.zeros(8))


def _record_search(monkeypatch) -> list:
    """The (problem, settings) of every `optimise run` that reaches the steady search, which is
    replaced by a recorder that stops the run with a one-line error (exit status 2)."""
    import optimise._steady as steady

    seen = []

    def recording(problem, settings, **kw):
        seen.append((problem, settings))
        raise UserInputError("stop here")

    monkeypatch.setattr(steady, "steady_search", recording)
    return seen


def test_cli_profile_options_reach_the_problem(tmp_path, capsys, monkeypatch):
    """`optimise run --profile` and each profile variable's bounds option: the problem the
    steady search receives has `ProfileBounds` with those bounds (the search itself is not run)."""
    seen = _record_search(monkeypatch)
    args = [
        "run",
        "--profile",
        "--end-offset-mm",
        "0,0.5",
        "--corner-radius-mm",
        "0.35,0.45",
        "--rib-curvature-per-m",
        "0,2",
        "--rib-tangent-height-mm",
        "0.2,1.0",
        "--flange-height-mm",
        "1.95,2.2",
        "--out",
        str(tmp_path / "run"),
    ]
    assert cli.main(args) == 2
    assert "stop here" in capsys.readouterr().err
    ((problem, _),) = seen
    assert isinstance(problem.bounds, ProfileBounds)
    e = problem.bounds.engineering()
    assert e["end_offset_mm"] == pytest.approx([0, 0.5])
    assert e["corner_radius_mm"] == pytest.approx([0.35, 0.45])
    assert e["rib_curvature_per_m"] == pytest.approx([0, 2])
    assert e["rib_tangent_height_mm"] == pytest.approx([0.2, 1.0])
    assert e["flange_height_mm"] == pytest.approx([1.95, 2.2])
    assert e["end_radius_mm"] == pytest.approx([60, 120])


def test_profile_search_defaults_to_one_start_of_three_iterations(tmp_path, capsys, monkeypatch):
    """Without `--starts` and `--iterations` the profile search runs one start of three
    iterations, as examples/optimise_profile.toml; the three-variable steady search keeps two
    starts of four (the search itself is not run)."""
    import optimise._steady as steady

    seen = []

    def recording(problem, settings, **kw):
        seen.append((problem.num_variables, kw["num_starts"], kw["num_iterations"]))
        raise UserInputError("stop here")

    monkeypatch.setattr(steady, "steady_search", recording)
    for extra in (["--profile"], []):
        assert cli.main(["run", *extra, "--out", str(tmp_path / f"run{len(extra)}")]) == 2
    assert seen == [(8, 1, 3), (3, 2, 4)]
    assert capsys.readouterr().err.count("stop here") == 2


def test_toml_profile_switch_and_errors(tmp_path, capsys, monkeypatch):
    from optimise._cli_settings import bounds_of
    from optimise._toml import load_optimise_toml

    f = tmp_path / "p.toml"
    f.write_text("[search]\nprofile = true\n[bounds]\nend_offset_mm = [0.0, 0.2]\n")
    s = load_optimise_toml(str(f))
    b = bounds_of(s)
    assert isinstance(b, ProfileBounds) and b.end_offset == pytest.approx((0.0, 0.2e-3))
    assert isinstance(bounds_of({}), opt.Bounds)
    f.write_text("[search]\nprofile = 1\n")
    with pytest.raises(UserInputError, match="search.profile = 1: expected true or false"):
        load_optimise_toml(str(f))
    assert cli.main(["run", "--profile", "--objective", "startup", "--out", str(tmp_path / "x")]) == 2
    assert "a profile search needs the steady objective" in capsys.readouterr().err


def test_meridians_match_their_closed_forms(tmp_path):
    x = np.array([90 * MM, 0.3 * MM, 0.4 * MM, 3.0, 0.8 * MM, 1.6 * DEG, 2.0 * MM, 0.15 * MM])
    m = face_meridians(BEARING, x, num=401)
    a, h = (np.asarray(v) * MM for v in m["end"])
    b = ProfileVariables.from_array(jnp.asarray(x)).apply(BEARING)
    d, length = float(b.roller.diameter), float(b.roller.length)
    # the apex: the ridge circle rho = e (h = D/2 - e) protrudes e_p beyond the flat end plane
    apex = length / 2 + float(face_protrusion(b.roller, faces_of(b)))
    assert a.max() == pytest.approx(apex, abs=1e-9)  # sampled within 0.01 mm of the ridge
    assert h[np.argmax(a)] == pytest.approx(d / 2 - 0.3 * MM, abs=d / 400)
    # the corner ends on the roller's cylinder at the corner circle's axial position
    assert a[-1] == pytest.approx(length / 2 - 0.4 * MM, abs=1e-12) and h[-1] == pytest.approx(0, abs=1e-15)
    # continuous where the arc meets the corner (the limited circle)
    assert np.max(np.abs(np.diff(a))) < 5e-5
    # the rib: its foot half the clearance beyond the apex on the cone of layback theta_f; the
    # arc of radius R_rib = 1/3 m touches that cone at h_t and falls behind it (towards the
    # roller) by the arc's sag R_rib - sqrt(R_rib^2 - u_t^2) along the cone's normal
    rx, rh = (np.asarray(v) * MM for v in m["rib"])
    theta, r_rib, h_t = 1.6 * DEG, 1 / 3.0, 0.8 * MM
    cone = apex + 0.075 * MM + rh * math.tan(theta)
    u_t = (rh - h_t) / math.cos(theta)
    np.testing.assert_allclose(
        (rx - cone) * math.cos(theta), -(r_rib - np.sqrt(r_rib**2 - u_t**2)), atol=1e-15
    )
    assert plot_faces(
        BEARING, {"a": x, "b": ProfileVariables.of(BEARING).as_array()}, tmp_path / "f.png"
    ).exists()


# -- limits on what the faces are designed for besides PV: Lambda and the flash temperature ---


@pytest.mark.parametrize(
    "kw,text",
    [
        (dict(min_film_parameter=0.0), "min_film_parameter = 0.0: must be > 0"),
        (dict(min_film_parameter=float("nan")), "min_film_parameter = nan"),
        (dict(max_flash_temperature=-5.0), "max_flash_temperature = -5.0: must be > 0 K"),
        (dict(max_friction_power=float("inf")), "max_friction_power = inf: must be > 0 W"),
    ],
)
def test_bad_limits_are_one_line(kw, text):
    with pytest.raises(UserInputError, match=text):
        opt.SteadySettings(**kw)


def _record(film, flash, friction=float("nan"), friction_gradient=None):
    return evaluation.PointRecord(
        value=1.0,
        ci=(0.9, 1.1),
        gradient=np.zeros(3),
        gradient_stderr=np.zeros(3),
        corner_margin=1e-4,
        measured_corner_margin=1e-4,
        measured_at=np.zeros(3),
        corner_contact_share=0.0,
        settled=True,
        simulated=True,
        film_parameter_low=film,
        flash_temperature_high=flash,
        friction_power_high=friction,
        friction_gradient=friction_gradient,
    )


def test_friction_limit_has_the_frozen_load_gradient_of_its_worst_point():
    """The friction-power limit's constraint row is -dP/du of the operating point of the
    smallest margin (its frozen-load estimate, W per unit box, scaled by 1 W), so the
    epsilon-constraint search steps away from a friction limit it approaches; the film and
    flash limits keep zero rows; a point without an estimate gives a zero row."""
    import optimise._steady as steady

    settings = opt.SteadySettings(min_film_parameter=1.5, max_friction_power=12.0)
    per = [
        _record(2.0, 60.0, 10.0, np.array([1.0, -2.0, 0.0])),
        _record(1.7, 90.0, 11.5, np.array([3.0, 0.5, 0.0])),
    ]
    jac = evaluation.limit_jacobian(settings, per)
    np.testing.assert_array_equal(jac, [[0.0, 0.0, 0.0], [-3.0, -0.5, 0.0]])
    margins = evaluation.limit_margins(settings, per)
    held, held_jac = steady.scaled_limits(settings, margins, jac)
    problem = opt.make_problem(BEARING, OP)
    u = jnp.full(3, 0.5)
    c, jc = steady.constraints(problem, u, 1e-4, u, held, held_jac)
    np.testing.assert_allclose(jc[5:], [[0.0, 0.0, 0.0], [-3.0, -0.5, 0.0]])
    np.testing.assert_allclose(c[6], 0.5 - problem.tighten)
    unknown = evaluation.limit_jacobian(settings, [_record(2.0, 60.0, 10.0)])
    assert np.all(unknown == 0) and unknown.shape == (2, 3)


def test_limit_margins_take_the_worst_measured_point():
    import optimise._steady as steady

    settings = opt.SteadySettings(min_film_parameter=1.5, max_flash_temperature=80.0, max_friction_power=12.0)
    assert settings.limits == (("film_parameter", 1.5), ("flash_temperature", 80.0), ("friction_power", 12.0))
    assert steady.constraint_names(settings)[-3:] == ("film_parameter", "flash_temperature", "friction_power")
    per = [
        _record(2.0, 60.0, 10.0),
        _record(1.7, 90.0, 11.0),
        _record(float("nan"), float("nan"), float("nan")),
    ]
    np.testing.assert_allclose(evaluation.limit_margins(settings, per), [0.2, -10.0, 1.0])
    # no point measured a film (no flange contact): nothing to limit
    unmeasured = evaluation.limit_margins(settings, [_record(float("nan"), float("nan"), float("nan"))])
    assert np.all(np.isinf(unmeasured)) and unmeasured.shape == (3,)
    scaled, _ = steady.scaled_limits(settings, unmeasured)
    assert np.all(scaled == steady.UNMEASURED_LIMIT)
    assert evaluation.limit_margins(opt.SteadySettings(), per).shape == (0,)


def test_limits_are_held_constraints_and_decide_feasibility():
    import optimise._steady as steady
    from optimise._state import History

    problem = opt.make_problem(BEARING, OP)
    settings = opt.SteadySettings(min_film_parameter=1.5, max_flash_temperature=80.0)
    u = jnp.full(3, 0.5)  # two limits set: seven constraints
    limits, _ = steady.scaled_limits(settings, [0.2, -10.0])
    np.testing.assert_allclose(limits, [2.0, -1.0])
    c, jc = steady.constraints(problem, u, 1e-4, u, limits)
    c0, jc0 = steady.constraints(problem, u, 1e-4, u)
    assert c.shape == (7,) and jc.shape == (7, 3)
    np.testing.assert_array_equal(c[:5], c0)
    np.testing.assert_array_equal(jc[:5], jc0)
    np.testing.assert_allclose(c[5:], limits - problem.tighten)
    assert np.all(jc[5:] == 0)
    # an evaluation over its flash limit is infeasible, however good its objective
    h = History()
    for margins, objective in (([1e-4] * 5 + [0.2, -10.0], 1.0), ([1e-4] * 5 + [0.2, 5.0], 2.0)):
        h.append(
            dict(
                x=[np.zeros(3)],
                objective=[objective],
                ci=[(objective - 0.1, objective + 0.1)],
                gradient=[np.zeros(3)],
                gradient_stderr=[np.zeros(3)],
                margins=[np.array(margins)],
                wall_s=[1.0],
                simulated_ms=[1.0],
                points_simulated=[np.ones(1, bool)],
                corner_risk=[1e-4],
            )
        )
    assert steady.choose(History(**h.as_arrays()), "best") == (1, 0)


def test_cli_limits_reach_the_settings(tmp_path, capsys, monkeypatch):
    seen = _record_search(monkeypatch)
    args = [
        "run",
        "--min-film-parameter",
        "1.5",
        "--max-flash-temperature-K",
        "80",
        "--max-friction-power-W",
        "12",
        "--out",
        str(tmp_path / "r"),
    ]
    assert cli.main(args) == 2
    assert seen[0][1].limits == (
        ("film_parameter", 1.5),
        ("flash_temperature", 80.0),
        ("friction_power", 12.0),
    )
    assert cli.main(["run", "--min-film-parameter", "-1", "--out", str(tmp_path / "s")]) == 2
    assert "min_film_parameter = -1.0: must be > 0" in capsys.readouterr().err
