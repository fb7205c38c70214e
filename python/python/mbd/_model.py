"""Models: read from model files, built in code, edited for ensembles, run."""

from __future__ import annotations

import copy
import json
import os
import warnings
from typing import Any, Dict, List, Mapping, Optional, Sequence, Union

from . import _mbd
from ._errors import InvalidArgumentError, ModelError
from ._result import Result, RunOptions, RunStats

PathLike = Union[str, "os.PathLike[str]"]


def _model_from_json(text: str) -> "Model":
    """Rebuilds a pickled model (its model file as JSON)."""
    return Model.from_str(text, "json")


class Model:
    """A validated multibody model: planar bodies, joints, forces, sensors, and spatial bodies
    and joints.

    Read one from a model file (``.toml`` or ``.json``, see ``docs/model-files.md``), from a
    string, or build one with :class:`ModelBuilder`; then :meth:`run` it with any solver of
    :func:`mbd.solvers`. A model pickles as its model file (JSON), and :meth:`with_parameters`
    gives a copy with other masses, stiffnesses, gravity or initial values (what
    :func:`mbd.ensemble` varies).

    >>> import mbd
    >>> m = mbd.Model.from_file("examples/models/slider_crank_spring.toml")
    >>> m.bodies, m.dof
    (['crank', 'rod', 'slider'], 1)
    >>> r = m.run("symplectic:2", t_end=0.5, h=1e-3, every=10)
    >>> r.q.shape, r.columns[:2]
    ((51, 9), ['t', 'crank.x'])
    """

    __slots__ = ("_core",)

    def __init__(self, core: "_mbd.CoreModel") -> None:
        self._core = core

    # -- reading and writing -------------------------------------------------------------
    @classmethod
    def from_file(cls, path: PathLike) -> "Model":
        """Reads a model file, TOML or JSON by its extension (tabulated time functions'
        CSV files relative to its folder). Raises :class:`mbd.ModelError`."""
        return cls(_mbd.CoreModel.from_path(os.fspath(path)))

    @classmethod
    def from_str(cls, text: str, format: str = "toml") -> "Model":
        """Parses a model file's text; ``format`` is ``"toml"`` or ``"json"``.

        >>> Model.from_str('{"bodies": [{"name": "b", "mass": 1, "inertia": 1}]}', "json").bodies
        ['b']
        """
        if format not in ("toml", "json"):
            raise InvalidArgumentError(
                f"unknown model format {format!r}: use \"toml\" or \"json\""
            )
        return cls(_mbd.CoreModel.from_text(text, format))

    @classmethod
    def from_dict(cls, d: Mapping[str, Any]) -> "Model":
        """Builds a model from a model file's content as a dict (the JSON form)."""
        return cls.from_str(json.dumps(d), "json")

    def to_json(self) -> str:
        """The model file as JSON (bodies in their centre-of-mass frames)."""
        return self._core.to_json()

    def to_toml(self) -> str:
        """The model file as TOML."""
        return self._core.to_toml()

    def to_dict(self) -> Dict[str, Any]:
        """The model file as a dict (edit it and pass it to :meth:`from_dict`)."""
        d: Dict[str, Any] = json.loads(self.to_json())
        return d

    def save(self, path: PathLike) -> None:
        """Writes the model file, TOML or JSON by the extension."""
        p = os.fspath(path)
        text = self.to_json() if p.endswith(".json") else self.to_toml()
        with open(p, "w", encoding="utf-8") as f:
            f.write(text)

    def __reduce__(self) -> Any:
        return (_model_from_json, (self.to_json(),))

    # -- what it holds --------------------------------------------------------------------
    def _describe(self) -> Dict[str, Any]:
        return self._core.describe()

    @property
    def bodies(self) -> List[str]:
        """The bodies' names."""
        return list(self._describe()["bodies"])

    @property
    def spatial_bodies(self) -> List[str]:
        """The spatial (3D) bodies' names (docs/spatial.md)."""
        return list(self._describe()["spatial_bodies"])

    @property
    def spatial_point_masses(self) -> List[str]:
        """The spatial point masses' names (``kind = "point_mass"`` in ``spatial_bodies``)."""
        return list(self._describe()["spatial_point_masses"])

    @property
    def spatial_joints(self) -> List[str]:
        """The spatial joints' names."""
        return list(self._describe()["spatial_joints"])

    @property
    def spatial_forces(self) -> List[str]:
        """The names of the force elements on spatial bodies."""
        return list(self._describe()["spatial_forces"])

    @property
    def joints(self) -> List[str]:
        """The joints' names (point masses add a ``<name>:point_mass`` joint)."""
        return list(self._describe()["joints"])

    @property
    def forces(self) -> List[str]:
        """The force elements' names."""
        return list(self._describe()["forces"])

    @property
    def coordinates(self) -> List[str]:
        """The coordinate names, in the order of ``Result.q``'s columns."""
        return list(self._describe()["coordinates"])

    @property
    def dof(self) -> int:
        """The degrees of freedom (coordinates less independent constraint equations)."""
        return int(self._describe()["dof"])

    @property
    def gravity(self) -> List[float]:
        """The gravity vector ``[gx, gy]``, m/s^2."""
        return list(self._describe()["gravity"])

    def __repr__(self) -> str:
        d = self._describe()
        spatial = (
            f"{len(d['spatial_bodies'])} spatial bodies, {len(d['spatial_joints'])} spatial joints, "
            if d["spatial_bodies"]
            else ""
        )
        return (
            f"<mbd.Model {len(d['bodies'])} bodies, {len(d['joints'])} joints, "
            f"{spatial}{len(d['forces'])} forces, {d['dof']} DOF>"
        )

    # -- running ---------------------------------------------------------------------------
    def run(
        self,
        solver: str = "symplectic:2",
        t_end: float = 1.0,
        h: Optional[float] = None,
        tol: Optional[float] = None,
        *,
        every: int = 1,
        reactions: bool = False,
        drift_tol: Optional[float] = None,
        drift_guard: bool = True,
        max_steps: int = 1_000_000_000,
        atol: Optional[float] = None,
        warn: bool = True,
    ) -> Result:
        """Runs the model from its consistent initial state at ``t = 0`` to ``t_end``, exactly
        as ``mbd run MODEL --solver SOLVER --t-end T_END --h H`` (or ``--tol TOL``) does: the
        same columns and, bit for bit, the same numbers. The GIL is released while it runs.

        ``every`` keeps every k-th step (and the last state); ``reactions`` adds the joint
        reactions; ``drift_tol`` / ``drift_guard=False`` loosen or turn off the drift guard;
        ``atol`` (with ``tol``) is the absolute part of the adaptive tolerance, in the model's
        units (``--atol``; default ``tol``);
        ``warn`` issues the warnings ``mbd run`` prints (initial values changed by the
        consistent-state projection, redundant equations, what the solver does not deliver on
        this model, e.g. the modified-Lagrangian schemes' plain order with drivers) as
        :class:`UserWarning`.

        Raises :class:`mbd.InvalidSolverSpec`, :class:`mbd.InvalidArgumentError`,
        :class:`mbd.SolveError` (or a subclass), :class:`mbd.ModelError`.

        >>> import mbd
        >>> r = mbd.Model.from_file("examples/models/manipulator.json").run(
        ...     "tangent:dopri5", t_end=0.5, tol=1e-8)
        >>> r.stats.stop, r.stats.rejected >= 0
        ('end', True)
        """
        opts = RunOptions(
            solver=solver,
            t_end=float(t_end),
            h=None if h is None else float(h),
            tol=None if tol is None else float(tol),
            every=int(every),
            reactions=bool(reactions),
            drift_tol=None if drift_tol is None else float(drift_tol),
            drift_guard=bool(drift_guard),
            max_steps=int(max_steps),
            atol=None if atol is None else float(atol),
        )
        return self.run_with(opts, warn=warn)

    def run_with(self, options: RunOptions, *, warn: bool = True) -> Result:
        """:meth:`run` with a :class:`RunOptions`."""
        _check_options(options)
        columns, data, n, stats = self._core.run(**options.to_dict())
        result = Result(columns, data, n, RunStats(**stats), options)
        if warn:
            for w in result.stats.warnings:
                warnings.warn(w, UserWarning, stacklevel=3)
        return result

    # -- editing ---------------------------------------------------------------------------
    def with_parameters(
        self,
        *,
        gravity: Optional[Sequence[float]] = None,
        mass: Optional[Mapping[str, float]] = None,
        inertia: Optional[Mapping[str, float]] = None,
        stiffness: Optional[Mapping[str, float]] = None,
        damping: Optional[Mapping[str, float]] = None,
        position: Optional[Mapping[str, Sequence[float]]] = None,
        velocity: Optional[Mapping[str, Sequence[float]]] = None,
    ) -> "Model":
        """A copy with other parameters, edited in its model file and validated again:

        * ``gravity``: ``[gx, gy]``;
        * ``mass``, ``inertia``: ``{body: value}``;
        * ``stiffness``, ``damping``: ``{force element: value}`` (spring-dampers, rotary
          spring-dampers);
        * ``position``, ``velocity``: ``{body: [x, y, theta]}`` initial values of the body
          (``[xdot, ydot, thetadot]``; the consistent-state projection still applies).

        Unknown names raise :class:`mbd.ModelError` naming them; invalid values raise it too
        (from the model's validation).

        >>> import mbd
        >>> m = mbd.Model.from_file("examples/models/slider_crank_spring.toml")
        >>> m.with_parameters(mass={"slider": 2.0}).to_dict()["bodies"][2]["mass"]
        2.0
        """
        d = copy.deepcopy(self.to_dict())
        if gravity is not None:
            g = [float(x) for x in gravity]
            if len(g) != 2:
                raise InvalidArgumentError(f"gravity must be [gx, gy], got {gravity!r}")
            d["gravity"] = g
        bodies = {b["name"]: b for b in d.get("bodies", [])}
        forces = {f["name"]: f for f in d.get("forces", [])}

        def edit(table: Dict[str, Dict[str, Any]], what: str, key: str,
                 values: Optional[Mapping[str, Any]], vector: bool = False) -> None:
            for name, value in (values or {}).items():
                if name not in table:
                    raise ModelError(
                        f"{what} '{name}' is not in the model (it has: "
                        f"{', '.join(table) or 'none'})"
                    ).with_element(name)
                if vector:
                    v = [float(x) for x in value]
                    if len(v) != 3:
                        raise InvalidArgumentError(
                            f"{key} of '{name}' must be [x, y, theta], got {value!r}"
                        )
                    table[name][key] = v
                else:
                    if key not in table[name] and what == "force element":
                        raise ModelError(
                            f"force element '{name}' ({table[name].get('type')}) has no {key}"
                        ).with_element(name)
                    table[name][key] = float(value)

        edit(bodies, "body", "mass", mass)
        edit(bodies, "body", "inertia", inertia)
        edit(forces, "force element", "stiffness", stiffness)
        edit(forces, "force element", "damping", damping)
        edit(bodies, "body", "position", position, vector=True)
        edit(bodies, "body", "velocity", velocity, vector=True)
        return Model.from_dict(d)


def _check_options(o: RunOptions) -> None:
    if o.every < 1:
        raise InvalidArgumentError(f"every must be at least 1, got {o.every}")
    if o.max_steps < 1:
        raise InvalidArgumentError(f"max_steps must be at least 1, got {o.max_steps}")
    if o.h is not None and o.tol is not None:
        raise InvalidArgumentError("give h or tol, not both")
    if o.tol is not None and not o.tol > 0:
        raise InvalidArgumentError(f"tol must be positive, got {o.tol}")
    if o.atol is not None and o.tol is None:
        raise InvalidArgumentError("atol needs tol (adaptive steps)")
    if o.atol is not None and not (o.atol > 0 and o.atol < float("inf")):
        raise InvalidArgumentError(f"atol must be positive and finite, got {o.atol}")
    if o.drift_tol is not None and not o.drift_tol > 0:
        raise InvalidArgumentError(f"drift_tol must be positive, got {o.drift_tol}")


class ModelBuilder:
    """Builds a model in code, element by element, as a model file (the same fields as
    ``docs/model-files.md``); :meth:`build` validates it into a :class:`Model`.

    Points are in each body's frame (its centre of mass), angles in rad; ``"ground"`` is the
    fixed frame.

    >>> import mbd
    >>> b = mbd.ModelBuilder(gravity=(0.0, -9.81))
    >>> b.add_body("link", mass=1.0, inertia=1 / 12, position=(0.5, 0.0, 0.0))
    'link'
    >>> b.add_revolute("pin", "ground", (0.0, 0.0), "link", (-0.5, 0.0))
    'pin'
    >>> m = b.build()
    >>> m.dof, m.run("symplectic:2", t_end=0.1, h=0.01).stats.steps
    (1, 10)
    """

    def __init__(self, gravity: Sequence[float] = (0.0, 0.0)) -> None:
        self._d: Dict[str, Any] = {
            "gravity": [float(x) for x in gravity],
            "bodies": [],
            "joints": [],
            "forces": [],
            "sensors": [],
        }

    def set_gravity(self, gx: float, gy: float) -> "ModelBuilder":
        """Sets the gravity vector, m/s^2."""
        self._d["gravity"] = [float(gx), float(gy)]
        return self

    def add_body(
        self,
        name: str,
        mass: float,
        inertia: float,
        position: Sequence[float] = (0.0, 0.0, 0.0),
        velocity: Sequence[float] = (0.0, 0.0, 0.0),
        inputs: Sequence[str] = (),
    ) -> str:
        """Adds a rigid body (mass kg, inertia kg m^2 about its centre of mass, initial pose
        ``[x, y, theta]`` and velocity); ``inputs`` marks initial values to keep exactly
        (``"d_theta"``, ...). Returns its name."""
        body: Dict[str, Any] = {
            "name": name,
            "mass": float(mass),
            "inertia": float(inertia),
            "position": [float(x) for x in position],
            "velocity": [float(x) for x in velocity],
        }
        if inputs:
            body["inputs"] = list(inputs)
        self._d["bodies"].append(body)
        return name

    def add_rod(self, name: str, mass: float, length: float,
                position: Sequence[float] = (0.0, 0.0, 0.0),
                velocity: Sequence[float] = (0.0, 0.0, 0.0)) -> str:
        """Adds a slender rod (inertia ``m l^2 / 12``)."""
        return self.add_body(name, mass, mass * length * length / 12.0, position, velocity)

    def add_point_mass(self, name: str, mass: float,
                       position: Sequence[float] = (0.0, 0.0),
                       velocity: Sequence[float] = (0.0, 0.0)) -> str:
        """Adds a particle (``x``, ``y`` only)."""
        self._d["bodies"].append({
            "name": name,
            "kind": "point_mass",
            "mass": float(mass),
            "position": [float(position[0]), float(position[1]), 0.0],
            "velocity": [float(velocity[0]), float(velocity[1]), 0.0],
        })
        return name

    def add_revolute(self, name: str, body_a: str, point_a: Sequence[float],
                     body_b: str, point_b: Sequence[float]) -> str:
        """Adds a pin joint: ``point_a`` on ``body_a`` and ``point_b`` on ``body_b`` coincide."""
        self._d["joints"].append({
            "type": "revolute", "name": name,
            "body_a": body_a, "point_a": _pt(point_a),
            "body_b": body_b, "point_b": _pt(point_b),
        })
        return name

    def add_prismatic(self, name: str, body_a: str, point_a: Sequence[float],
                      body_b: str, point_b: Sequence[float],
                      axis: Sequence[float], angle: float = 0.0) -> str:
        """Adds a slider: ``point_b`` stays on the line through ``point_a`` along ``axis`` (in
        ``body_a``'s frame) and ``theta_b - theta_a = angle``."""
        self._d["joints"].append({
            "type": "prismatic", "name": name,
            "body_a": body_a, "point_a": _pt(point_a),
            "body_b": body_b, "point_b": _pt(point_b),
            "axis": _pt(axis), "angle": float(angle),
        })
        return name

    def add_angle_driver(self, name: str, body_a: str, body_b: str,
                         f: Union[float, Mapping[str, Any]]) -> str:
        """Adds a driver ``theta_b - theta_a = f(t)``: ``f`` a number (constant) or a time
        function as in model files, e.g. ``{"kind": "polynomial", "coeffs": [0.0, 2.0]}``."""
        self._d["joints"].append({
            "type": "angle_driver", "name": name,
            "body_a": body_a, "body_b": body_b, "f": _timefn(f),
        })
        return name

    def add_joint(self, spec: Mapping[str, Any]) -> str:
        """Adds any joint as its model-file table (``{"type": "weld", "name": ..., ...}``)."""
        self._d["joints"].append(dict(spec))
        return str(spec.get("name"))

    def add_spring_damper(self, name: str, body_a: str, point_a: Sequence[float],
                          body_b: str, point_b: Sequence[float], stiffness: float,
                          rest_length: float, damping: float = 0.0) -> str:
        """Adds a linear spring-damper between two points (N/m, m, N s/m)."""
        self._d["forces"].append({
            "type": "spring_damper", "name": name,
            "body_a": body_a, "point_a": _pt(point_a),
            "body_b": body_b, "point_b": _pt(point_b),
            "stiffness": float(stiffness), "damping": float(damping),
            "rest_length": float(rest_length),
        })
        return name

    def add_rotary_spring_damper(self, name: str, body_a: str, body_b: str,
                                 stiffness: float, damping: float = 0.0,
                                 rest_angle: float = 0.0) -> str:
        """Adds a torsional spring-damper on ``theta_b - theta_a``."""
        self._d["forces"].append({
            "type": "rotary_spring_damper", "name": name,
            "body_a": body_a, "body_b": body_b, "stiffness": float(stiffness),
            "damping": float(damping), "rest_angle": float(rest_angle),
        })
        return name

    def add_force(self, name: str, body: str, fx: Union[float, Mapping[str, Any]],
                  fy: Union[float, Mapping[str, Any]],
                  point: Sequence[float] = (0.0, 0.0)) -> str:
        """Adds a load at a body point, global components (numbers or time functions)."""
        self._d["forces"].append({
            "type": "force", "name": name, "body": body, "point": _pt(point),
            "fx": _timefn(fx), "fy": _timefn(fy),
        })
        return name

    def add_torque(self, name: str, body: str, torque: Union[float, Mapping[str, Any]]) -> str:
        """Adds an applied torque (a number or a time function, N m)."""
        self._d["forces"].append({
            "type": "torque", "name": name, "body": body, "torque": _timefn(torque),
        })
        return name

    def add_sensor(self, spec: Mapping[str, Any]) -> str:
        """Adds a sensor as its model-file table (``{"type": "point", "name": "tip",
        "body": "link", "point": [0.5, 0.0]}``): its columns join the results."""
        self._d["sensors"].append(dict(spec))
        return str(spec.get("name"))

    def to_dict(self) -> Dict[str, Any]:
        """The model file built so far."""
        d = copy.deepcopy(self._d)
        if not d["sensors"]:
            del d["sensors"]
        return d

    def build(self) -> Model:
        """Validates the model (raises :class:`mbd.ModelError` naming the element at fault)."""
        return Model.from_dict(self.to_dict())


def _pt(p: Sequence[float]) -> List[float]:
    return [float(p[0]), float(p[1])]


def _timefn(f: Union[float, int, Mapping[str, Any]]) -> Dict[str, Any]:
    if isinstance(f, (int, float)):
        return {"kind": "constant", "value": float(f)}
    return dict(f)
