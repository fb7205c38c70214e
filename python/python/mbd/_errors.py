"""The exceptions of :mod:`mbd`, one class per kind of failure of the Rust library.

Every exception carries, besides its message (``str(e)``, the Rust error's text):

* ``kind``: the Rust variant's name (``"Singular"``, ``"UnknownBody"``, ...);
* ``element``: the element at fault where the error names one (a body, joint, force or
  equation name, a solver spec), else ``None``;
* ``details``: the variant's other fields (``{"t": 0.357, "parameter": "mass", ...}``).

They pickle with these attributes (a failed ensemble member's exception travels back from a
Dask worker).

>>> import mbd
>>> try:
...     mbd.Model.from_str('[[bodies]]\\nname = "a"\\nmass = -1.0\\ninertia = 1.0\\n', "toml")
... except mbd.ModelError as e:
...     print(e.element, e.details["parameter"])
a mass
"""

from __future__ import annotations

from typing import Any, Dict, Optional


class MbdError(Exception):
    """The base of every error the library raises."""

    def __init__(
        self,
        message: str = "",
        *,
        kind: Optional[str] = None,
        element: Optional[str] = None,
        details: Optional[Dict[str, Any]] = None,
    ) -> None:
        super().__init__(message)
        self.kind: str = kind or type(self).__name__
        self.element: Optional[str] = element
        self.details: Dict[str, Any] = dict(details or {})

    def with_element(self, element: Optional[str]) -> "MbdError":
        """Sets ``element`` and returns the exception (for ``raise ...with_element(name)``)."""
        self.element = element
        return self

    @property
    def message(self) -> str:
        """The error's message (the Rust error's text)."""
        return str(self.args[0]) if self.args else ""


class ModelError(MbdError):
    """A model that cannot be read or built: a parse error, an unknown body, a bad parameter
    (``details["parameter"]``), a duplicate name; ``element`` names the element."""


class SolveError(MbdError):
    """A run that failed: Newton did not converge, a non-finite state, a refused model."""


class SingularConfigurationError(SolveError):
    """The mechanism reached a singular configuration: ``details["t"]`` the time,
    ``details["detail"]`` the equations near dependence or the failing pivot."""


class ConstraintDriftError(SolveError):
    """The constraints drifted beyond the drift guard (``element`` is the joint)."""


class StepSizeError(SolveError):
    """Adaptive steps failed: the step fell below its minimum, or the attempt budget ran out."""


class InvalidSolverSpec(SolveError, ValueError):
    """An unknown solver or a bad option of a solver spec string (``element`` is the spec)."""


class InvalidArgumentError(MbdError, ValueError):
    """A run's options refused: a step size, an end time, a step budget, a format name."""


__all__ = [
    "MbdError",
    "ModelError",
    "SolveError",
    "SingularConfigurationError",
    "ConstraintDriftError",
    "StepSizeError",
    "InvalidSolverSpec",
    "InvalidArgumentError",
]
