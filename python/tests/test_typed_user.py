"""The typed user program runs: every call of the package, end to end."""

from __future__ import annotations

from pathlib import Path

from conftest import PICKER
from typed_user import main


def test_every_call_runs(keypair: tuple[Path, Path]) -> None:
    secret, public = keypair
    assert main(PICKER, public_key=public, secret_key=secret) == 0
