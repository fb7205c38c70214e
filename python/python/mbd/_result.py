"""Run options, run statistics and results."""

from __future__ import annotations

from dataclasses import asdict, dataclass, field
from typing import Any, Dict, List, Optional, Sequence

import numpy as np


@dataclass(frozen=True)
class RunOptions:
    """The options of one run, named like the flags of ``mbd run``.

    ``h`` gives fixed steps, ``tol`` adaptive ones (solvers marked adaptive in
    :func:`mbd.solvers`); ``every`` keeps every k-th step (and always the first and the last
    state); ``reactions`` adds each joint's ``JOINT.fx``, ``JOINT.fy``, ``JOINT.mz``;
    ``drift_tol`` / ``drift_guard`` set or turn off the drift guard; ``max_steps`` is the step
    budget; ``atol`` (with ``tol``) the absolute part of the adaptive tolerance in the model's
    units (default ``tol``: a coordinate ``y`` may err by ``atol + tol |y|``).

    >>> RunOptions("rk4", t_end=1.0, h=0.01).every
    1
    """

    solver: str
    t_end: float
    h: Optional[float] = None
    tol: Optional[float] = None
    every: int = 1
    reactions: bool = False
    drift_tol: Optional[float] = None
    drift_guard: bool = True
    max_steps: int = 1_000_000_000
    atol: Optional[float] = None

    def to_dict(self) -> Dict[str, Any]:
        """The options as a dict (the keyword arguments of :meth:`mbd.Model.run`)."""
        return asdict(self)


@dataclass(frozen=True)
class RunStats:
    """What a run did: ``steps`` (accepted), ``rejected`` (adaptive runs), ``stop`` (``"end"``,
    ``"observer"`` or ``"event"``), ``wall_time`` (s, the integration alone), ``rows`` kept,
    the energy error ``e_h`` (max ``|H - H0| / |H0|``), the constraint errors ``e_phi`` and
    ``e_phidot`` (max over every step), ``not_conserved`` (why ``H`` is not conserved, or
    ``None``), ``energy_balance`` (its residual relative to ``max |H|`` where it is not),
    ``stepped_over`` (grid times at a singular configuration that fixed steps stepped over) and
    ``skipped_outputs`` (of those, the ones without a row), and the warnings ``mbd run``
    prints."""

    steps: int
    rejected: int
    stop: str
    wall_time: float
    rows: int
    newton_iterations: int = 0
    rhs_evals: int = 0
    near_singular_steps: int = 0
    stepped_over: int = 0
    skipped_outputs: int = 0
    min_step: float = 0.0
    max_step: float = 0.0
    e_h: float = 0.0
    e_phi: float = 0.0
    e_phidot: float = 0.0
    not_conserved: Optional[str] = None
    energy_balance: Optional[float] = None
    warnings: List[str] = field(default_factory=list)


class Result:
    """The output of one run: the columns of ``mbd run`` (the same names, the same numbers).

    * ``t`` (1-D), ``q``, ``v`` (2-D, one row per output time, one column per coordinate in
      the order of ``coordinates``), ``H`` (the energy);
    * ``data``: every column (2-D, read-only), ``columns``: their names;
    * ``result["crank_pivot.fx"]``: any column by name (residuals ``max_abs_phi`` and
      ``max_abs_phidot``; reactions with ``reactions=True``; the model's sensors; the energy
      balance ``W_external``, ``E_dissipated``, ``energy_balance`` where ``H`` is not conserved);
    * ``stats``: :class:`RunStats`; ``options``: the :class:`RunOptions` of the run;
      ``parameters``: an ensemble member's parameter values (``{}`` otherwise).

    >>> import mbd
    >>> r = mbd.Model.from_file("examples/models/pendulum.toml").run("rk4", t_end=0.1, h=0.01)
    >>> r.t.shape, r.q.shape[0], r.stats.steps
    ((11,), 11, 10)
    """

    def __init__(
        self,
        columns: Sequence[str],
        data: np.ndarray,
        n_coordinates: int,
        stats: RunStats,
        options: Optional[RunOptions] = None,
        parameters: Optional[Dict[str, Any]] = None,
    ) -> None:
        self.columns: List[str] = list(columns)
        data = np.asarray(data, dtype=np.float64)
        data.flags.writeable = False
        self.data: np.ndarray = data
        self.n_coordinates: int = int(n_coordinates)
        self.stats: RunStats = stats
        self.options: Optional[RunOptions] = options
        self.parameters: Dict[str, Any] = dict(parameters or {})
        self._index = {c: i for i, c in enumerate(self.columns)}

    @property
    def error(self) -> None:
        """``None``: a :class:`Result` is a run that succeeded (an ensemble's failed member holds
        the exception instead)."""
        return None

    @property
    def t(self) -> np.ndarray:
        """The output times, s (1-D)."""
        return self.data[:, 0]

    @property
    def q(self) -> np.ndarray:
        """The coordinates (rows: output times; columns: ``coordinates``)."""
        return self.data[:, 1 : 1 + self.n_coordinates]

    @property
    def v(self) -> np.ndarray:
        """The velocities (rows: output times; columns: ``coordinates``)."""
        n = self.n_coordinates
        return self.data[:, 1 + n : 1 + 2 * n]

    @property
    def H(self) -> np.ndarray:  # noqa: N802 - the energy's name in the papers and the CSV
        """The total energy ``H`` (kinetic plus potential), J."""
        return self["H"]

    @property
    def coordinates(self) -> List[str]:
        """The coordinate names (``crank.x``, ``crank.y``, ``crank.theta``, ...)."""
        return self.columns[1 : 1 + self.n_coordinates]

    @property
    def residuals(self) -> np.ndarray:
        """The constraint residuals ``max_abs_phi``, ``max_abs_phidot`` (2 columns)."""
        return self.data[:, [self._index["max_abs_phi"], self._index["max_abs_phidot"]]]

    def reaction(self, joint: str) -> np.ndarray:
        """The reaction of ``joint`` (run with ``reactions=True``): columns ``fx``, ``fy``
        (force on the joint's second body, global axes, N) and ``mz`` (N m)."""
        return np.stack([self[f"{joint}.{c}"] for c in ("fx", "fy", "mz")], axis=1)

    @property
    def sensor_columns(self) -> List[str]:
        """The columns after the state, ``H``, the residuals and the reactions: the model's
        sensors and the energy balance."""
        fixed = 1 + 2 * self.n_coordinates + 3
        return [
            c
            for c in self.columns[fixed:]
            if not c.endswith((".fx", ".fy", ".mz"))
        ]

    def __getitem__(self, name: str) -> np.ndarray:
        try:
            return self.data[:, self._index[name]]
        except KeyError:
            raise KeyError(
                f"no column {name!r}; the columns are: {', '.join(self.columns)}"
            ) from None

    def __contains__(self, name: object) -> bool:
        return name in self._index

    def keys(self) -> List[str]:
        """The column names."""
        return list(self.columns)

    def to_dict(self) -> Dict[str, np.ndarray]:
        """``{column: values}`` (e.g. for ``pandas.DataFrame(result.to_dict())``)."""
        return {c: self.data[:, i] for i, c in enumerate(self.columns)}

    def __len__(self) -> int:
        return int(self.data.shape[0])

    def __repr__(self) -> str:
        solver = self.options.solver if self.options else "?"
        return (
            f"<mbd.Result {self.data.shape[0]} rows x {len(self.columns)} columns, "
            f"solver {solver}, {self.stats.steps} steps, stop {self.stats.stop}>"
        )

    def __getstate__(self) -> Dict[str, Any]:
        state = dict(self.__dict__)
        del state["_index"]
        return state

    def __setstate__(self, state: Dict[str, Any]) -> None:
        self.__dict__.update(state)
        data = np.array(self.data, dtype=np.float64)
        data.flags.writeable = False
        self.data = data
        self._index = {c: i for i, c in enumerate(self.columns)}
