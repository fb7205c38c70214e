"""The docstrings' examples run (from the repository root, where their paths point)."""

from __future__ import annotations

import doctest

import pytest

import mbd
from mbd import _ensemble, _errors, _model, _result

MODULES = [mbd, _model, _result, _ensemble, _errors]


@pytest.mark.parametrize("module", MODULES, ids=[m.__name__ for m in MODULES])
def test_docstring_examples(module):
    failures, tried = doctest.testmod(module, optionflags=doctest.ELLIPSIS)
    assert tried > 0 and failures == 0
