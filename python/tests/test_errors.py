"""Every exception type, raised by a real bad input, with its attributes; exceptions pickle."""

from __future__ import annotations

import math
import pickle

import pytest

import mbd

from conftest import MODELS

BAD_MASS = """
[[bodies]]
name = "arm"
mass = -1.0
inertia = 0.1
"""

UNKNOWN_BODY = """
[[bodies]]
name = "arm"
mass = 1.0
inertia = 0.1

[[joints]]
type = "revolute"
name = "pin"
body_a = "ground"
body_b = "wheel"
"""


def test_hierarchy():
    for cls in (mbd.ModelError, mbd.SolveError, mbd.InvalidArgumentError):
        assert issubclass(cls, mbd.MbdError)
    for cls in (mbd.SingularConfigurationError, mbd.ConstraintDriftError, mbd.StepSizeError,
                mbd.InvalidSolverSpec):
        assert issubclass(cls, mbd.SolveError)
    assert issubclass(mbd.InvalidSolverSpec, ValueError)
    assert issubclass(mbd.InvalidArgumentError, ValueError)


def test_model_errors_name_the_element():
    with pytest.raises(mbd.ModelError) as e:
        mbd.Model.from_str(BAD_MASS, "toml")
    assert e.value.kind == "InvalidParameter"
    assert "arm" in e.value.element
    assert e.value.details["parameter"] == "mass" and e.value.details["value"] == -1.0
    assert "mass" in str(e.value) and e.value.message == str(e.value)
    with pytest.raises(mbd.ModelError) as e:
        mbd.Model.from_str(UNKNOWN_BODY, "toml")
    assert e.value.kind == "UnknownBody" and e.value.details["body"] == "wheel"
    assert "pin" in e.value.element
    with pytest.raises(mbd.ModelError) as e:
        mbd.Model.from_str("bodies = [", "toml")
    assert e.value.kind == "Parse" and e.value.details["format"] == "toml"
    with pytest.raises(mbd.ModelError) as e:
        mbd.Model.from_file("no/such/model.toml")
    assert "no/such/model.toml" in str(e.value)


def test_invalid_solver_specs():
    m = mbd.Model.from_file(MODELS / "pendulum.toml")
    with pytest.raises(mbd.InvalidSolverSpec) as e:
        m.run("rk5", t_end=1.0, h=0.01)
    assert e.value.element == "rk5" and "tangent:rk4" in str(e.value)
    with pytest.raises(mbd.InvalidSolverSpec, match="given twice"):
        m.run("symplectic:2:gamma=1:gamma=2", t_end=1.0, h=0.01)
    with pytest.raises(ValueError):  # an InvalidSolverSpec is a ValueError too
        m.run("firefly-gauss:seed=x", t_end=1.0, h=0.01)


def test_invalid_arguments():
    m = mbd.Model.from_file(MODELS / "pendulum.toml")
    with pytest.raises(mbd.InvalidArgumentError) as e:
        m.run("rk4", t_end=1.0, h=-0.1)
    assert e.value.kind == "InvalidStep" and e.value.details["h"] == -0.1
    with pytest.raises(mbd.InvalidArgumentError, match="embedded error estimate"):
        m.run("rk4", t_end=1.0, tol=1e-6)
    with pytest.raises(mbd.InvalidArgumentError, match="not after"):
        m.run("rk4", t_end=0.0, h=0.01)
    with pytest.raises(mbd.InvalidArgumentError, match="give a step size"):
        m.run("rk4", t_end=1.0)
    with pytest.raises(mbd.InvalidArgumentError, match="every"):
        m.run("rk4", t_end=1.0, h=0.01, every=0)
    with pytest.raises(mbd.InvalidArgumentError, match="max_steps"):
        m.run("rk4", t_end=1.0, h=1e-3, max_steps=10)
    with pytest.raises(mbd.InvalidArgumentError, match="format"):
        mbd.Model.from_str("{}", "yaml")


def _parallelogram():
    """The parallelogram four-bar of the Rust tests (crank 1 m, ground 2 m, from 0.5 rad at
    6 rad/s): it passes its flat, singular configuration at about t = 1.45 s under gravity."""
    l, d, th, w = 1.0, 2.0, 0.5, 6.0
    s, c = math.sin(th), math.cos(th)
    a, vh = (l * c, l * s), (-0.5 * l * s * w, 0.5 * l * c * w)
    b = mbd.ModelBuilder(gravity=(0.0, -9.81))
    b.add_rod("crank", 1.0, l, (0.5 * a[0], 0.5 * a[1], th), (vh[0], vh[1], w))
    b.add_rod("coupler", 1.0, d, (a[0] + 0.5 * d, a[1], 0.0), (2 * vh[0], 2 * vh[1], 0.0))
    b.add_rod("rocker", 1.0, l, (d + 0.5 * a[0], 0.5 * a[1], th), (vh[0], vh[1], w))
    b.add_revolute("A0", "ground", (0, 0), "crank", (-0.5 * l, 0))
    b.add_revolute("A", "crank", (0.5 * l, 0), "coupler", (-0.5 * d, 0))
    b.add_revolute("B", "coupler", (0.5 * d, 0), "rocker", (0.5 * l, 0))
    b.add_revolute("B0", "ground", (d, 0), "rocker", (-0.5 * l, 0))
    return b.build()


def test_singular_configuration():
    with pytest.raises(mbd.SingularConfigurationError) as e:
        _parallelogram().run("index1:dopri5", t_end=1.5, h=1e-3, warn=False)
    assert e.value.kind == "Singular"
    assert 1.0 < e.value.details["t"] < 1.5 and "B0" in e.value.details["detail"]


def test_constraint_drift_names_the_joint():
    m = mbd.Model.from_file(MODELS / "four_bar.toml")
    with pytest.raises(mbd.ConstraintDriftError) as e:
        m.run("rk4", t_end=5.0, h=0.1)
    assert e.value.element == "o2" and e.value.details["t"] == 1.0
    assert e.value.details["residual"] > e.value.details["tolerance"]


def test_step_size_errors_and_plain_solve_errors():
    m = mbd.Model.from_file(MODELS / "manipulator.json")
    with pytest.raises(mbd.StepSizeError) as e:
        m.run("tangent:dopri5", t_end=1.0, tol=1e-30)
    assert e.value.kind == "StepSizeTooSmall"
    with pytest.raises(mbd.StepSizeError) as e:
        m.run("tangent:dopri5", t_end=1.0, tol=1e-12, max_steps=10)
    assert e.value.kind == "TooManyAttempts"
    with pytest.raises(mbd.SolveError) as e:
        mbd.Model.from_file(MODELS / "four_bar.toml").run("rk4", t_end=5.0, h=0.2)
    assert e.value.kind == "NonFinite" and type(e.value) is mbd.SolveError


def test_exceptions_pickle_with_their_attributes():
    try:
        mbd.Model.from_str(BAD_MASS, "toml")
    except mbd.ModelError as e:
        again = pickle.loads(pickle.dumps(e))
        assert type(again) is mbd.ModelError
        assert (again.kind, again.element, again.details, str(again)) == (
            e.kind, e.element, e.details, str(e))


def test_a_blow_up_is_a_drift_error_not_a_singular_configuration():
    # plain RK4 on the flyball governor's stiff dampers at ten times its stable step
    m = mbd.Model.from_file(MODELS / "flyball_governor.toml")
    with pytest.raises(mbd.ConstraintDriftError) as e:
        m.run("rk4", t_end=0.05, h=1e-3)
    d = e.value.details
    assert d["residual"] > 100 * d["tolerance"]
    assert e.value.element.startswith("arm")
    assert "blew up" in str(e.value)
    # at its stable step it runs
    m.run("rk4", t_end=0.01, h=1e-4)
