"""The API: shapes, accessors, the registry, the builder, pickling, the GIL."""

from __future__ import annotations

import pickle
import threading
import time

import numpy as np
import pytest

import mbd

from conftest import MODELS


@pytest.fixture(scope="module")
def slider():
    return mbd.Model.from_file(MODELS / "slider_crank_spring.toml")


def test_shapes_and_accessors(slider):
    r = slider.run("symplectic:2", t_end=0.1, h=1e-3, every=10, reactions=True)
    n = len(slider.coordinates)
    assert n == 9 and r.coordinates == slider.coordinates
    assert r.t.shape == (11,) and r.t.dtype == np.float64
    assert r.q.shape == (11, n) and r.v.shape == (11, n)
    assert r.data.shape == (11, len(r.columns))
    assert r.t[0] == 0.0 and r.t[-1] == pytest.approx(0.1, abs=1e-15)
    assert np.array_equal(r.q[:, 0], r["crank.x"])
    assert np.array_equal(r.v[:, 2], r["d_crank.theta"])
    assert np.array_equal(r.H, r["H"])
    assert r.residuals.shape == (11, 2)
    assert r.reaction("crank_pivot").shape == (11, 3)
    assert np.array_equal(r.reaction("crank_pivot")[:, 0], r["crank_pivot.fx"])
    assert "energy_balance" in r.sensor_columns
    with pytest.raises(KeyError, match="no column"):
        r["nope"]
    assert not r.data.flags.writeable
    s = r.stats
    assert (s.steps, s.rejected, s.stop, s.rows) == (100, 0, "end", 11)
    assert s.wall_time >= 0.0 and s.e_phi < 1e-9
    assert r.error is None and len(r) == 11 and "Result" in repr(r)


def test_every_keeps_the_last_state(slider):
    r = slider.run("rk4-projected", t_end=0.1, h=1e-3, every=30)
    assert list(np.round(r.t, 12)) == [0.0, 0.03, 0.06, 0.09, 0.1]


def test_adaptive_run_reports_rejections_and_steps():
    m = mbd.Model.from_file(MODELS / "manipulator.json")
    r = m.run("tangent:dopri5", t_end=1.0, tol=1e-6)
    assert r.stats.steps == len(r) - 1
    assert r.stats.min_step > 0 and r.stats.max_step >= r.stats.min_step


def test_atol_is_the_absolute_part_of_the_adaptive_tolerance():
    m = mbd.Model.from_file(MODELS / "pendulum.toml")
    loose = m.run("index1:dopri5", t_end=1.0, tol=1e-4)
    tight = m.run("index1:dopri5", t_end=1.0, tol=1e-4, atol=1e-10)
    assert tight.stats.steps > loose.stats.steps
    assert tight.options.atol == 1e-10
    with pytest.raises(mbd.InvalidArgumentError, match="atol needs tol"):
        m.run("index1:dopri5", t_end=1.0, h=1e-3, atol=1e-10)
    with pytest.raises(mbd.InvalidArgumentError, match="atol must be positive"):
        m.run("index1:dopri5", t_end=1.0, tol=1e-4, atol=-1.0)


def test_solvers_lists_the_registry():
    s = mbd.solvers()
    specs = [x["spec"] for x in s]
    assert {"rk4", "symplectic:2", "tangent:dopri5", "firefly-gauss"} <= set(specs)
    d = {x["spec"]: x for x in s}
    assert d["tangent:dopri5"]["adaptive"] and not d["rk4"]["adaptive"]
    assert d["symplectic:2"]["order"] == 4
    assert all(isinstance(x["description"], str) and x["description"] for x in s)


def test_model_properties_and_text_forms(slider):
    assert slider.bodies == ["crank", "rod", "slider"]
    assert slider.joints == ["crank_pivot", "crank_pin", "wrist_pin", "guide"]
    assert slider.forces == ["return_spring"]
    assert slider.dof == 1 and slider.gravity == [0.0, -9.81]
    for fmt, text in (("json", slider.to_json()), ("toml", slider.to_toml())):
        again = mbd.Model.from_str(text, fmt)
        assert again.to_json() == slider.to_json()
    assert "3 bodies" in repr(slider)


def test_builder_maps_onto_model_files():
    b = mbd.ModelBuilder()
    b.set_gravity(0.0, -9.81)
    b.add_body("crank", 1.0, 0.001875, position=(0.075, 0.0, 0.0), velocity=(0.0, 0.45, 6.0),
               inputs=["d_theta"])
    b.add_revolute("pivot", "ground", (0.0, 0.0), "crank", (-0.075, 0.0))
    b.add_torque("motor", "crank", {"kind": "harmonic", "amplitude": 0.1, "omega": 3.0})
    b.add_sensor({"type": "point", "name": "tip", "body": "crank", "point": [0.075, 0.0]})
    m = b.build()
    assert m.dof == 1 and m.forces == ["motor"]
    r = m.run("tangent:rk4", t_end=0.1, h=1e-3)
    assert "tip.x" in r and "tip.ay" in r
    assert r.v[0, 2] == 6.0  # the input kept


def test_reaction_and_energy_sensors(slider):
    d = slider.to_dict()
    d["sensors"] = [{"type": "reaction", "name": "pin", "joint": "crank_pin"},
                    {"type": "energy", "name": "all"}]
    m = mbd.Model.from_dict(d)
    r = m.run("rk4", t_end=0.05, h=1e-3)
    assert "pin.fx_body" in r and "pin.mz" in r
    assert (r["all.total"] == r["H"]).all()


def test_with_parameters_edits_the_model_file(slider):
    m = slider.with_parameters(gravity=[0.0, -1.62], mass={"slider": 2.0},
                               stiffness={"return_spring": 50.0}, damping={"return_spring": 0.0})
    d = m.to_dict()
    assert d["gravity"] == [0.0, -1.62] and d["bodies"][2]["mass"] == 2.0
    assert d["forces"][0]["stiffness"] == 50.0 and d["forces"][0]["damping"] == 0.0
    assert slider.to_dict()["bodies"][2]["mass"] == 0.5  # the original is unchanged
    with pytest.raises(mbd.ModelError) as e:
        slider.with_parameters(mass={"wheel": 1.0})
    assert e.value.element == "wheel"


def test_pickle_round_trips(slider):
    m2 = pickle.loads(pickle.dumps(slider))
    assert m2.to_json() == slider.to_json()
    r = slider.run("symplectic:1", t_end=0.05, h=1e-3)
    r2 = pickle.loads(pickle.dumps(r))
    assert np.array_equal(r.data, r2.data) and r2.columns == r.columns
    assert r2.stats == r.stats and r2.options == r.options
    assert not r2.data.flags.writeable
    assert np.array_equal(m2.run("symplectic:1", t_end=0.05, h=1e-3).data, r.data)
    o = mbd.RunOptions("rk4", 1.0, h=0.01, every=3)
    assert pickle.loads(pickle.dumps(o)) == o
    assert np.array_equal(slider.run_with(mbd.RunOptions("rk4", 0.05, h=1e-3)).data,
                          slider.run("rk4", t_end=0.05, h=1e-3).data)


def test_the_gil_is_released_while_rust_runs(slider):
    ticks = []
    done = threading.Event()

    def work():
        slider.run("symplectic:2", t_end=8.0, h=1e-4, every=1000)
        done.set()

    th = threading.Thread(target=work)
    t0 = time.perf_counter()
    th.start()
    while not done.is_set():
        ticks.append(time.perf_counter())
        time.sleep(0.005)
    th.join()
    elapsed = time.perf_counter() - t0
    # the main thread ran all along: about one tick per 5 ms of the run
    assert elapsed > 0.05, "the run was too short to tell"
    assert len(ticks) > 0.3 * elapsed / 0.005


def test_a_spatial_model_from_a_file_runs():
    m = mbd.Model.from_file(MODELS / "heavy_top.toml")
    assert m.spatial_bodies == ["top"] and m.spatial_joints == ["tip"] and m.dof == 3
    assert m.spatial_forces == []
    p = mbd.Model.from_file(MODELS / "spatial_spring_pendulum.toml")
    assert p.spatial_forces == ["strut", "thruster"]
    assert "1 spatial bodies" in repr(m)
    r = m.run("tangent:rk4", t_end=0.2, h=1e-3)
    assert "top.d3z" in r
    # the centre of mass stays 0.5 m from the tip
    radius = (r["top.x"] ** 2 + r["top.y"] ** 2 + r["top.z"] ** 2) ** 0.5
    assert abs(radius - 0.5).max() < 1e-12


def test_a_solver_caveat_is_a_warning():
    # the driven arm without its force elements: the modified schemes run it at the plain order
    d = mbd.Model.from_file(MODELS / "driven_three_link_arm.json").to_dict()
    d["forces"] = []
    m = mbd.Model.from_dict(d)
    with pytest.warns(UserWarning, match=r"order 2 \(not 4\)"):
        r = m.run("symplectic:1:modified", t_end=0.05, h=1e-2)
    assert any("drivers" in w for w in r.stats.warnings)
    # a model without drivers gets no caveat
    r = mbd.Model.from_file(MODELS / "pendulum.toml").run(
        "symplectic:1:modified", t_end=0.05, h=1e-2, warn=False
    )
    assert r.stats.warnings == []


def _body(name, mass, inertia, x, vy, w):
    """A planar body's TOML table, on the x axis at rest but for the velocity (0, vy, w)."""
    return (
        '[[bodies]]\nname = "{}"\nmass = {}\ninertia = {}\n'
        "position = [{!r}, 0.0, 0.0]\nvelocity = [0.0, {!r}, {!r}]\n"
    ).format(name, mass, inertia, x, vy, w)


def _joint(kind, name, a, xa, b, xb):
    """A joint's TOML table between points on the x axes of bodies `a` and `b`."""
    return (
        '[[joints]]\ntype = "{}"\nname = "{}"\nbody_a = "{}"\npoint_a = [{}, 0.0]\n'
        'body_b = "{}"\npoint_b = [{}, 0.0]\n'
    ).format(kind, name, a, xa, b, xb)

def _motor(body, w):
    """An angle driver turning `body` at `w` rad/s from 0 against the ground, as TOML."""
    return (
        '[[joints]]\ntype = "angle_driver"\nname = "motor"\nbody_a = "ground"\n'
        'body_b = "{}"\nf = {{ kind = "polynomial", coeffs = [0.0, {!r}] }}\n'
    ).format(body, w)



def test_a_grid_time_on_a_singular_configuration_is_stepped_over(tmp_path):
    # an isosceles slider-crank (crank and rod 0.5 m) driven at 2 pi rad/s from 0: its dead
    # point (rod folded onto the crank) at t = 0.25 s lies on the grid of h = 1e-3
    w = 2 * np.pi
    text = "gravity = [0.0, -9.81]\n"
    text += _body("crank", 1.0, 1 / 48, 0.25, 0.25 * w, w)
    text += _body("rod", 1.0, 1 / 48, 0.75, 0.25 * w, -w)
    text += _body("slider", 0.5, 0.001, 1.0, 0.0, 0.0)
    text += _joint("revolute", "pivot", "ground", 0.0, "crank", -0.25)
    text += _joint("revolute", "pin", "crank", 0.25, "rod", -0.25)
    text += _joint("revolute", "wrist", "rod", 0.25, "slider", 0.0)
    text += _joint("prismatic", "guide", "ground", 0.0, "slider", 0.0)
    text += "axis = [1.0, 0.0]\nangle = 0.0\n"
    text += _motor("crank", w)
    path = tmp_path / "isosceles_slider_crank.toml"
    path.write_text(text)
    m = mbd.Model.from_file(path)
    r = m.run("tangent:rk4", t_end=0.5, h=1e-3, warn=False)
    assert (r.stats.stepped_over, r.stats.skipped_outputs) == (1, 1)
    # no row at the dead point itself; every other one on the exact motion
    assert len(r) == 500 and not np.any(np.isclose(r.t, 0.25, rtol=0, atol=1e-12))
    assert np.abs(r["slider.x"] - np.cos(w * r.t)).max() < 1e-9
    assert any("stepped over" in s for s in r.stats.warnings)
    # off the grid nothing is stepped over
    r = m.run("tangent:rk4", t_end=0.5, h=1.1e-3, warn=False)
    assert (r.stats.stepped_over, r.stats.skipped_outputs) == (0, 0)


def test_a_singular_start_is_named_and_not_taken_for_redundancy(tmp_path):
    # a parallelogram four-bar driven from its flat position: one equation depends on the
    # others at the start only, so the mechanism has no redundant equation and no freedom
    w = np.pi
    text = "gravity = [0.0, -9.81]\n"
    text += _body("crank0", 1.0, 1 / 48, 0.25, 0.25 * w, w)
    text += _body("crank1", 1.0, 1 / 48, 1.25, 0.25 * w, w)
    text += _body("coupler", 2.0, 1 / 6, 1.0, 0.5 * w, 0.0)
    text += _joint("revolute", "pivot0", "ground", 0.0, "crank0", -0.25)
    text += _joint("revolute", "pin0", "crank0", 0.25, "coupler", -0.5)
    text += _joint("revolute", "pivot1", "ground", 1.0, "crank1", -0.25)
    text += _joint("revolute", "pin1", "crank1", 0.25, "coupler", 0.5)
    text += _motor("crank0", w)
    path = tmp_path / "flat_four_bar.toml"
    path.write_text(text)
    m = mbd.Model.from_file(path)
    r = m.run("rk4-projected", t_end=0.5, h=1e-3, warn=False)
    assert any("initial configuration is singular" in s for s in r.stats.warnings)
    assert not any("redundant" in s for s in r.stats.warnings)
    assert np.abs(r["crank1.theta"] - w * r.t).max() < 1e-9
