"""mbd: planar and spatial rigid multibody dynamics as DAEs, from Python.

The Rust library ``mbd`` (the solvers of three papers and an RK4 baseline) behind a small API:

* :class:`Model` — read a model file (``Model.from_file``), a string (``Model.from_str``), or
  build one (:class:`ModelBuilder`); ``model.run(solver, t_end, h=...)`` or ``tol=...``;
* :class:`Result` — ``t``, ``q``, ``v``, ``H``, every column of ``mbd run`` by name, ``stats``;
* :func:`solvers` — the registry's solvers (spec, order, adaptive, description);
* :func:`ensemble` — one run per parameter value, on threads or a Dask cluster;
* exceptions: :class:`MbdError` and its subclasses.

>>> import mbd
>>> r = mbd.Model.from_file("examples/models/pendulum.toml").run("symplectic:2", t_end=1.0, h=1e-3)
>>> round(float(abs(r.H[-1] - r.H[0])), 6)
0.0

The distribution is ``mbd-dae`` (like the Rust facade crate); the import name is ``mbd``.
"""

from __future__ import annotations

from typing import Any, Dict, List

from . import _mbd
from ._ensemble import EnsembleResult, ensemble, member_seed
from ._errors import (
    ConstraintDriftError,
    InvalidArgumentError,
    InvalidSolverSpec,
    MbdError,
    ModelError,
    SingularConfigurationError,
    SolveError,
    StepSizeError,
)
from ._model import Model, ModelBuilder
from ._result import Result, RunOptions, RunStats

__version__ = "0.1.0"


def solvers() -> List[Dict[str, Any]]:
    """The solvers of the registry, in the order ``mbd solvers`` lists them: one dict per
    variant with ``spec`` (the string :meth:`Model.run` takes), ``order``, ``adaptive``
    (takes ``tol``), ``description``, ``label``, ``refuses``, ``family``, ``syntax``.

    >>> [s["spec"] for s in solvers()][:2]
    ['rk4', 'rk4-projected']
    """
    return list(_mbd.solvers())


__all__ = [
    "Model",
    "ModelBuilder",
    "Result",
    "RunOptions",
    "RunStats",
    "EnsembleResult",
    "ensemble",
    "member_seed",
    "solvers",
    "MbdError",
    "ModelError",
    "SolveError",
    "SingularConfigurationError",
    "ConstraintDriftError",
    "StepSizeError",
    "InvalidSolverSpec",
    "InvalidArgumentError",
]
