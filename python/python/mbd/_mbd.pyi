"""Type stubs of the Rust core ``mbd._mbd`` (the public API is in :mod:`mbd`)."""

from typing import Any, Dict, List, Optional, Sequence, Tuple, Union

import numpy as np
import numpy.typing as npt

from ._errors import MbdError

RunTuple = Tuple[List[str], npt.NDArray[np.float64], int, Dict[str, Any]]

class CoreModel:
    """A validated model (a Rust ``System``)."""

    @staticmethod
    def from_path(path: str) -> CoreModel: ...
    @staticmethod
    def from_text(text: str, format: str) -> CoreModel: ...
    def to_json(self) -> str: ...
    def to_toml(self) -> str: ...
    def describe(self) -> Dict[str, Any]: ...
    def run(
        self,
        solver: str,
        t_end: float,
        h: Optional[float] = None,
        tol: Optional[float] = None,
        every: int = 1,
        reactions: bool = False,
        drift_tol: Optional[float] = None,
        drift_guard: bool = True,
        max_steps: int = 1_000_000_000,
        atol: Optional[float] = None,
    ) -> RunTuple: ...

def run_many(
    members: Sequence[Tuple[CoreModel, Dict[str, Any]]], threads: Optional[int] = None
) -> List[Union[RunTuple, MbdError]]: ...
def solvers() -> List[Dict[str, Any]]: ...
def parse_solver(spec: str) -> Tuple[str, bool]: ...
