"""A run from Python equals `mbd run` on the same model and options, bit for bit: both keep
the rows of the same collector, and the CLI writes shortest round-trip decimals, so parsing its
CSV (or JSON) gives the exact numbers."""

from __future__ import annotations

import json
import subprocess

import numpy as np
import pytest

import mbd

from conftest import MODELS

CASES = [
    # model, solver, python options, cli flags
    ("slider_crank_spring.toml", "symplectic:2", dict(t_end=0.5, h=1e-3, every=7),
     ["--t-end", "0.5", "--h", "1e-3", "--every", "7"]),
    ("manipulator.json", "tangent:dopri5", dict(t_end=1.0, tol=1e-8),
     ["--t-end", "1", "--tol", "1e-8"]),
    ("four_bar.toml", "rk4", dict(t_end=0.3, h=2e-3, reactions=True),
     ["--t-end", "0.3", "--h", "2e-3", "--reactions"]),
    ("driven_three_link_arm.json", "rk4-projected", dict(t_end=0.4, h=1e-3, every=10),
     ["--t-end", "0.4", "--h", "1e-3", "--every", "10"]),
    ("pendulum.toml", "firefly-gauss:seed=3", dict(t_end=0.05, h=1e-2),
     ["--t-end", "0.05", "--h", "1e-2"]),
    ("point_mass_pendulum.toml", "index1:dopri5", dict(t_end=0.5, h=1e-2, drift_guard=False),
     ["--t-end", "0.5", "--h", "1e-2", "--no-drift-guard"]),
    ("pendulum.toml", "index1:dopri5", dict(t_end=1.0, tol=1e-4, atol=1e-10),
     ["--t-end", "1", "--tol", "1e-4", "--atol", "1e-10"]),
]


def _cli_csv(cli, model, solver, flags, tmp_path):
    out = tmp_path / "out.csv"
    subprocess.run(
        [str(cli), "run", str(MODELS / model), "--solver", solver, *flags, "--out", str(out)],
        check=True, capture_output=True,
    )
    with open(out) as f:
        header = f.readline().strip().split(",")
    data = np.loadtxt(out, delimiter=",", skiprows=1, ndmin=2)
    return header, data


@pytest.mark.parametrize("model,solver,opts,flags", CASES, ids=[c[0] + ":" + c[1] for c in CASES])
def test_run_equals_the_cli_csv(cli, tmp_path, model, solver, opts, flags):
    header, data = _cli_csv(cli, model, solver, flags, tmp_path)
    r = mbd.Model.from_file(MODELS / model).run(solver, warn=False, **opts)
    assert r.columns == header
    assert r.data.shape == data.shape
    assert np.array_equal(r.data, data, equal_nan=True)


def test_run_equals_the_cli_json_and_its_summary(cli, tmp_path):
    out = tmp_path / "out.json"
    subprocess.run(
        [str(cli), "run", str(MODELS / "slider_crank_spring.toml"), "--solver", "tangent:rk4",
         "--t-end", "0.3", "--h", "1e-3", "--every", "4", "--reactions", "--out", str(out)],
        check=True, capture_output=True,
    )
    doc = json.loads(out.read_text())
    r = mbd.Model.from_file(MODELS / "slider_crank_spring.toml").run(
        "tangent:rk4", t_end=0.3, h=1e-3, every=4, reactions=True)
    assert r.columns == doc["columns"]
    assert np.array_equal(r.data, np.array(doc["rows"], dtype=float))
    assert r.stats.steps == doc["summary"]["steps"] == 300
    assert r.stats.e_h == doc["summary"]["e_h"]
    assert r.stats.e_phi == doc["summary"]["e_phi"]
    # the damper makes H not conserved: the energy balance's columns are there, as in the CLI
    assert "energy_balance" in r and r.stats.not_conserved is not None


def test_a_model_built_in_code_equals_its_file(cli, tmp_path):
    b = mbd.ModelBuilder(gravity=(0.0, -9.81))
    b.add_rod("link1", 1.0, 1.0, position=(0.5, 0.0, 0.0))
    b.add_rod("link2", 1.0, 1.0, position=(1.5, 0.0, 0.0))
    b.add_revolute("pin1", "ground", (0.0, 0.0), "link1", (-0.5, 0.0))
    b.add_revolute("pin2", "link1", (0.5, 0.0), "link2", (-0.5, 0.0))
    b.add_rotary_spring_damper("spring", "link1", "link2", 5.0, 0.1)
    m = b.build()
    path = tmp_path / "double.toml"
    m.save(path)
    out = tmp_path / "o.csv"
    subprocess.run([str(cli), "run", str(path), "--solver", "symplectic:1", "--t-end", "0.2",
                    "--h", "1e-3", "--out", str(out)], check=True, capture_output=True)
    data = np.loadtxt(out, delimiter=",", skiprows=1)
    assert np.array_equal(m.run("symplectic:1", t_end=0.2, h=1e-3).data, data)
