"""Ensembles: one run per parameter value, on local threads or on a Dask cluster."""

from __future__ import annotations

import uuid
from typing import Any, Dict, List, Mapping, Optional, Sequence, Tuple, Union

from . import _mbd
from ._errors import InvalidArgumentError, MbdError
from ._model import Model, _check_options
from ._result import Result, RunOptions, RunStats

_MASK = (1 << 64) - 1

Member = Union[Result, MbdError]


def member_seed(root: int, index: int) -> int:
    """The seed of ensemble member ``index`` from the root seed ``root`` (SplitMix64 of
    ``root + (index + 1) * golden gamma``): distinct members get unrelated seeds, and the same
    root gives the same seeds wherever the members run.

    >>> member_seed(0, 0) == member_seed(0, 0) != member_seed(0, 1)
    True
    """
    z = (int(root) + (int(index) + 1) * 0x9E3779B97F4A7C15) & _MASK
    z = ((z ^ (z >> 30)) * 0xBF58476D1CE4E5B9) & _MASK
    z = ((z ^ (z >> 27)) * 0x94D049BB133111EB) & _MASK
    return z ^ (z >> 31)


class EnsembleResult(list):  # type: ignore[type-arg]
    """The members' outcomes in the order of the parameters: a :class:`mbd.Result` for each
    member that ran, the exception (an :class:`mbd.MbdError`) for each that failed.

    ``parameters[i]`` is member ``i``'s parameter values; ``failures`` lists ``(i, exception)``;
    :meth:`summary` says how many ran and why the others failed; :meth:`raise_first` raises the
    first failure.
    """

    def __init__(self, members: Sequence[Member], parameters: Sequence[Dict[str, Any]]):
        super().__init__(members)
        self.parameters: List[Dict[str, Any]] = list(parameters)

    @property
    def failures(self) -> List[Tuple[int, MbdError]]:
        """``(index, exception)`` of every failed member."""
        return [(i, m) for i, m in enumerate(self) if isinstance(m, MbdError)]

    @property
    def ok(self) -> bool:
        """Whether every member ran."""
        return not self.failures

    def results(self) -> List[Result]:
        """The results of the members that ran (in order)."""
        return [m for m in self if isinstance(m, Result)]

    def summary(self) -> str:
        """``"8 members: 7 ran, 1 failed"`` and one line per failure."""
        lines = [f"{len(self)} members: {len(self) - len(self.failures)} ran, "
                 f"{len(self.failures)} failed"]
        for i, e in self.failures:
            lines.append(f"  member {i} {self.parameters[i]}: {type(e).__name__}: {e}")
        return "\n".join(lines)

    def raise_first(self) -> None:
        """Raises the first failed member's exception, if any."""
        for _, e in self.failures:
            raise e

    def __reduce__(self) -> Any:
        return (EnsembleResult, (list(self), self.parameters))


_PER_BODY = ("mass", "inertia", "position", "velocity")
_PER_FORCE = ("stiffness", "damping")


def _members(params: Dict[str, Any]) -> Tuple[int, List[Dict[str, Any]]]:
    """Splits the parameter lists into one dict per member (zipped, not a product)."""
    lengths: Dict[str, int] = {}
    for key, value in params.items():
        if value is None:
            continue
        if key in _PER_BODY or key in _PER_FORCE:
            if not isinstance(value, Mapping):
                raise InvalidArgumentError(
                    f"{key} takes {{name: [values per member]}}, got {type(value).__name__}"
                )
            for name, vals in value.items():
                lengths[f"{key}[{name}]"] = len(vals)
        else:
            lengths[key] = len(value)
    if not lengths:
        raise InvalidArgumentError(
            "an ensemble needs at least one parameter list (gravity, mass, inertia, stiffness, "
            "damping, position, velocity, h, tol, seeds)"
        )
    sizes = set(lengths.values())
    if len(sizes) != 1:
        raise InvalidArgumentError(
            "every parameter list needs one value per member; lengths: "
            + ", ".join(f"{k}={v}" for k, v in lengths.items())
        )
    n = sizes.pop()
    members: List[Dict[str, Any]] = [{} for _ in range(n)]
    for key, value in params.items():
        if value is None:
            continue
        for i in range(n):
            if isinstance(value, Mapping):
                members[i].setdefault(key, {})
                for name, vals in value.items():
                    members[i][key][name] = vals[i]
            else:
                members[i][key] = value[i]
    return n, members


def _solver_with_seed(solver: str, root: Optional[int], index: int) -> str:
    """Gives a firefly-Gauss member its own seed (from the root: ``seed=``, else the spec's
    ``:seed=N``, else 0); other solvers are deterministic and keep their spec."""
    parts = solver.split(":")
    if parts[0] != "firefly-gauss":
        return solver
    spec_root = 0
    kept = [parts[0]]
    for p in parts[1:]:
        if p.startswith("seed="):
            try:
                spec_root = int(p[5:])
            except ValueError:
                return solver  # the registry reports the bad seed
        else:
            kept.append(p)
    seed = member_seed(spec_root if root is None else root, index)
    return ":".join(kept + [f"seed={seed}"])


def _run_member(model: Model, options: RunOptions, parameters: Dict[str, Any]) -> Member:
    """Runs one member (on a Dask worker): its result, or its exception as a value."""
    try:
        r = model.run_with(options, warn=False)
    except MbdError as e:
        return e
    r.parameters = dict(parameters)
    return r


def ensemble(
    model: Model,
    solver: str = "symplectic:2",
    t_end: float = 1.0,
    h: Union[None, float, Sequence[float]] = None,
    tol: Union[None, float, Sequence[float]] = None,
    *,
    gravity: Optional[Sequence[Sequence[float]]] = None,
    mass: Optional[Mapping[str, Sequence[float]]] = None,
    inertia: Optional[Mapping[str, Sequence[float]]] = None,
    stiffness: Optional[Mapping[str, Sequence[float]]] = None,
    damping: Optional[Mapping[str, Sequence[float]]] = None,
    position: Optional[Mapping[str, Sequence[Sequence[float]]]] = None,
    velocity: Optional[Mapping[str, Sequence[Sequence[float]]]] = None,
    seed: Optional[int] = None,
    every: int = 1,
    reactions: bool = False,
    drift_tol: Optional[float] = None,
    drift_guard: bool = True,
    max_steps: int = 1_000_000_000,
    client: Any = None,
    threads: Optional[int] = None,
    retries: int = 2,
) -> EnsembleResult:
    """Runs ``model`` once per parameter value and returns the outcomes in parameter order.

    Parameter lists (all of one length, one value per member, zipped):

    * ``gravity=[[gx, gy], ...]``;
    * ``mass={"crank": [m0, m1, ...]}``, ``inertia={...}``: per body;
    * ``stiffness={"spring": [...]}``, ``damping={...}``: per spring-damper;
    * ``position={"crank": [[x, y, theta], ...]}``, ``velocity={...}``: initial values;
    * ``h=[...]`` or ``tol=[...]``: the step or tolerance per member (a single number is the
      same for every member).

    Each member's model is the model file edited by :meth:`Model.with_parameters`. A
    ``firefly-gauss`` member gets the seed :func:`member_seed` ``(root, index)``, the root being
    ``seed`` (else the spec's ``:seed=N``, else 0), so an ensemble's results do not depend on
    where or in which order members run.

    ``client=None`` runs the members on local threads (Rust, the GIL released; ``threads``
    caps them); a ``dask.distributed.Client`` submits one task per member to its workers
    (``retries`` times again if a worker is lost) and gathers them in order. The results are
    the same bits either way.

    A member that fails (an invalid value, a solver that stops) does not stop the others: its
    slot holds the exception, ``EnsembleResult.failures`` and ``.summary()`` list them.

    >>> import mbd
    >>> m = mbd.Model.from_file("examples/models/slider_crank_spring.toml")
    >>> ens = mbd.ensemble(m, "symplectic:2", t_end=0.2, h=1e-3,
    ...                    stiffness={"return_spring": [100.0, 200.0, -1.0]})
    >>> [type(x).__name__ for x in ens]
    ['Result', 'Result', 'ModelError']
    """
    params: Dict[str, Any] = {
        "gravity": gravity,
        "mass": mass,
        "inertia": inertia,
        "stiffness": stiffness,
        "damping": damping,
        "position": position,
        "velocity": velocity,
    }
    if h is not None and tol is not None:
        raise InvalidArgumentError("give h or tol, not both")
    if isinstance(h, (list, tuple)):
        params["h"] = h
    if isinstance(tol, (list, tuple)):
        params["tol"] = tol
    n, members = _members(params)

    outcomes: List[Optional[Member]] = [None] * n
    jobs: List[Tuple[int, Model, RunOptions]] = []
    for i, p in enumerate(members):
        edits = {k: v for k, v in p.items() if k not in ("h", "tol")}
        try:
            m = model.with_parameters(**edits) if edits else model
            opts = RunOptions(
                solver=_solver_with_seed(solver, seed, i),
                t_end=float(t_end),
                h=float(p["h"]) if "h" in p else (None if h is None else float(h)),  # type: ignore[arg-type]
                tol=float(p["tol"]) if "tol" in p else (None if tol is None else float(tol)),  # type: ignore[arg-type]
                every=int(every),
                reactions=bool(reactions),
                drift_tol=drift_tol,
                drift_guard=bool(drift_guard),
                max_steps=int(max_steps),
            )
            _check_options(opts)
        except MbdError as e:
            outcomes[i] = e
            continue
        jobs.append((i, m, opts))

    if client is None:
        raw = _mbd.run_many([(m._core, o.to_dict()) for _, m, o in jobs], threads)
        for (i, _, o), r in zip(jobs, raw):
            if isinstance(r, MbdError):
                outcomes[i] = r
            else:
                columns, data, nq, stats = r
                outcomes[i] = Result(columns, data, nq, RunStats(**stats), o, members[i])
    else:
        token = uuid.uuid4().hex[:12]
        futures = [
            client.submit(
                _run_member, m, o, members[i],
                key=f"mbd-member-{token}-{i}", retries=retries, pure=False,
            )
            for i, m, o in jobs
        ]
        for (i, _, _), r in zip(jobs, client.gather(futures)):
            outcomes[i] = r
    return EnsembleResult(outcomes, members)  # type: ignore[arg-type]
