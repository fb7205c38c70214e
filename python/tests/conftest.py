"""Shared fixtures: the repository's paths and the `mbd` command-line program."""

from __future__ import annotations

import os
import shutil
import subprocess
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[2]
MODELS = REPO / "examples" / "models"


def _cli_candidates():
    if os.environ.get("MBD_CLI"):
        yield Path(os.environ["MBD_CLI"])
    target = os.environ.get("CARGO_TARGET_DIR")
    if target:
        yield Path(target) / "release" / "mbd"
    yield REPO / "target" / "release" / "mbd"


@pytest.fixture(scope="session")
def cli() -> Path:
    """The release `mbd` binary: $MBD_CLI, else target/release/mbd (built here if missing)."""
    for p in _cli_candidates():
        if p.is_file():
            return p
    cargo = shutil.which("cargo")
    if cargo is None:
        pytest.fail("no mbd binary (set MBD_CLI) and no cargo to build one")
    subprocess.run([cargo, "build", "--release", "-p", "mbd-cli"], cwd=REPO, check=True)
    for p in _cli_candidates():
        if p.is_file():
            return p
    pytest.fail("cargo build --release -p mbd-cli made no mbd binary where expected")


@pytest.fixture(autouse=True)
def _in_repo(monkeypatch):
    """Tests (and the docstring examples) use paths relative to the repository root."""
    monkeypatch.chdir(REPO)
