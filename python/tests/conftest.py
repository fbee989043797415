"""Shared fixtures: the picker robot's rules (api/tests/fixtures/picker.situ),
written for the embedded board, and the situ binary for making keys."""

from __future__ import annotations

import os
import shutil
import subprocess
from pathlib import Path

import pytest

import situ

ROOT = Path(__file__).resolve().parents[2]
PICKER = ROOT / "api" / "tests" / "fixtures" / "picker.situ"

pytest_plugins = ["pytester"]


@pytest.fixture
def picker_text() -> str:
    return PICKER.read_text()


@pytest.fixture
def picker() -> situ.Program:
    return situ.load_path(PICKER)


@pytest.fixture
def board(picker: situ.Program) -> situ.Board:
    return situ.Board(picker)


@pytest.fixture
def situ_bin() -> Path:
    """The command line, for what the package does not do (making keys)."""
    found = os.environ.get("SITU") or shutil.which("situ") or str(ROOT / "target" / "debug" / "situ")
    path = Path(found)
    assert path.exists(), f"the situ binary is needed to make keys: {path} (set SITU)"
    return path


@pytest.fixture
def keypair(tmp_path: Path, situ_bin: Path) -> tuple[Path, Path]:
    subprocess.run([str(situ_bin), "key", "new", str(tmp_path / "team")], check=True, capture_output=True)
    return tmp_path / "team.key", tmp_path / "team.pub"
