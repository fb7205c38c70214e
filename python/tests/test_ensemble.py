"""Ensembles: parameter order, per-member failures, local threads and Dask clusters give the
same bits, seeded FA-DAE members."""

from __future__ import annotations

import pickle

import numpy as np
import pytest

import mbd

from conftest import MODELS

distributed = pytest.importorskip("distributed")


@pytest.fixture(scope="module")
def slider():
    return mbd.Model.from_file(MODELS / "slider_crank_spring.toml")


GRAVITY = [[0.0, -9.81], [0.0, -1.62], [0.0, 0.0], [0.5, -3.71]]
KW = dict(t_end=0.2, h=1e-3, every=20)


def _local(slider):
    return mbd.ensemble(slider, "symplectic:2", gravity=GRAVITY,
                        mass={"slider": [0.5, 1.0, 2.0, 4.0]}, **KW)


def test_members_are_in_parameter_order(slider):
    ens = _local(slider)
    assert ens.ok and len(ens) == 4
    for i, r in enumerate(ens):
        assert r.parameters == {"gravity": GRAVITY[i], "mass": {"slider": [0.5, 1.0, 2.0, 4.0][i]}}
        one = slider.with_parameters(gravity=GRAVITY[i],
                                     mass={"slider": [0.5, 1.0, 2.0, 4.0][i]})
        assert np.array_equal(r.data, one.run("symplectic:2", **KW).data)
    assert not np.array_equal(ens[0].data, ens[1].data)


def test_every_parameter_kind(slider):
    ens = mbd.ensemble(
        slider, "tangent:rk4", t_end=0.05, h=[1e-3, 5e-4],
        inertia={"crank": [0.002, 0.003]}, stiffness={"return_spring": [100.0, 300.0]},
        damping={"return_spring": [0.0, 5.0]},
        position={"slider": [[0.59, 0.0, 0.0], [0.6, 0.0, 0.0]]},
        velocity={"crank": [[-0.3, 0.3, 6.0], [-0.3, 0.3, 5.0]]},
    )
    assert ens.ok, ens.summary()
    assert [r.stats.steps for r in ens] == [50, 100]
    assert [r.options.h for r in ens] == [1e-3, 5e-4]
    tol = mbd.ensemble(mbd.Model.from_file(MODELS / "manipulator.json"), "tangent:dopri5",
                       t_end=0.2, tol=[1e-4, 1e-9])
    assert tol[0].stats.steps < tol[1].stats.steps


def test_a_failing_member_is_reported_not_lost(slider):
    ens = mbd.ensemble(slider, "symplectic:2", t_end=0.05, h=1e-3,
                       stiffness={"return_spring": [100.0, -5.0, 200.0]})
    assert isinstance(ens[0], mbd.Result) and isinstance(ens[2], mbd.Result)
    assert isinstance(ens[1], mbd.ModelError)
    assert ens[1].details["parameter"] == "stiffness"
    assert [i for i, _ in ens.failures] == [1]
    assert "3 members: 2 ran, 1 failed" in ens.summary() and "member 1" in ens.summary()
    with pytest.raises(mbd.ModelError):
        ens.raise_first()
    # a member whose run fails (here a bad step) fails alone too
    ens = mbd.ensemble(slider, "rk4", t_end=0.05, h=[1e-3, -1.0])
    assert isinstance(ens[0], mbd.Result) and isinstance(ens[1], mbd.InvalidArgumentError)
    # and the outcome pickles, failures included
    again = pickle.loads(pickle.dumps(ens))
    assert isinstance(again[1], mbd.InvalidArgumentError) and again.parameters == ens.parameters


def test_mismatched_lists_are_refused(slider):
    with pytest.raises(mbd.InvalidArgumentError, match="one value per member"):
        mbd.ensemble(slider, "rk4", t_end=0.1, h=1e-3, gravity=[[0, -1]], mass={"rod": [1, 2]})
    with pytest.raises(mbd.InvalidArgumentError, match="at least one parameter"):
        mbd.ensemble(slider, "rk4", t_end=0.1, h=1e-3)


def test_fa_dae_members_are_seeded_and_deterministic():
    m = mbd.Model.from_file(MODELS / "pendulum.toml")
    kw = dict(t_end=0.03, h=1e-2, gravity=[[0.0, -9.81]] * 3)
    a = mbd.ensemble(m, "firefly-gauss", seed=11, **kw)
    b = mbd.ensemble(m, "firefly-gauss", seed=11, threads=1, **kw)
    assert a.ok
    for x, y in zip(a, b):
        assert np.array_equal(x.data, y.data)
    # the members share the model but not the seed: their swarms differ
    assert [r.options.solver for r in a] == [
        f"firefly-gauss:seed={mbd.member_seed(11, i)}" for i in range(3)]
    # a member equals a single run with its seed
    one = m.run(a[1].options.solver, t_end=0.03, h=1e-2)
    assert np.array_equal(one.data, a[1].data)


@pytest.fixture(scope="module")
def clusters():
    from distributed import Client, LocalCluster

    out = []
    for n in (2, 1):
        cluster = LocalCluster(n_workers=n, threads_per_worker=1, processes=True,
                               dashboard_address=":0")
        out.append((cluster, Client(cluster)))
    yield [c for _, c in out]
    for cluster, client in out:
        client.close()
        cluster.close()


def test_dask_clusters_give_the_local_bits(slider, clusters):
    local = _local(slider)
    fa_model = mbd.Model.from_file(MODELS / "pendulum.toml")
    fa_kw = dict(t_end=0.02, h=1e-2, gravity=[[0.0, -9.81], [0.0, -5.0]], seed=5)
    fa_local = mbd.ensemble(fa_model, "firefly-gauss", **fa_kw)
    for client in clusters:
        remote = mbd.ensemble(slider, "symplectic:2", gravity=GRAVITY,
                              mass={"slider": [0.5, 1.0, 2.0, 4.0]}, client=client, **KW)
        assert len(remote) == len(local)
        for x, y in zip(local, remote):
            assert np.array_equal(x.data, y.data) and x.columns == y.columns
            assert x.parameters == y.parameters
        fa_remote = mbd.ensemble(fa_model, "firefly-gauss", client=client, **fa_kw)
        for x, y in zip(fa_local, fa_remote):
            assert np.array_equal(x.data, y.data)
    # failures come back from the workers as exception objects, in their slots
    ens = mbd.ensemble(slider, "symplectic:2", t_end=0.05, h=[1e-3, -1.0, 1e-3],
                       mass={"crank": [1.0, 1.0, 0.0]}, client=clusters[0])
    assert isinstance(ens[0], mbd.Result)
    assert isinstance(ens[1], mbd.InvalidArgumentError)  # raised on a worker
    assert isinstance(ens[2], mbd.ModelError)  # refused before submitting
