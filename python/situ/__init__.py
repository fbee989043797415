"""situ: situation rules for robot navigation stacks, inside your own code.

Check, format, build and load ``.situ`` rules, run their tests and prove
their properties, and run a Bulletinboard in this process::

    import situ

    program = situ.load_path("robot.situ")
    board = situ.Board(program)
    board.post("BATT", at=0.0, charge=80.0)
    print(board.state, board.why())

Every call is the Rust library's (``situ-api``), the one the ``situ``
command line is a client of: the same checks, verdicts and admission rule.
"""

from __future__ import annotations

import json
import os
from typing import Optional, Sequence, Union

from . import _situ
from ._situ import (
    Agent,
    Batch,
    Board,
    Bundle,
    Change,
    Counters,
    Fact,
    Fired,
    Outcome,
    Program,
    Reloaded,
    Why,
)
from .errors import (
    BoardError,
    BundleError,
    Error,
    FindingsError,
    ReadError,
    RecordingError,
    SituSyntaxError,
    TrustError,
    WriteError,
)
from .findings import Counterexample, Finding, Place, PropertyResult, Report, Step, TestResult, report_of

__version__: str = _situ.__version__

PathLike = Union[str, "os.PathLike[str]"]
#: A field's value: a float (``f64``), an int (``i64``, or an ``f64``), a
#: bool, or a symbol's name.
Value = Union[float, int, bool, str]

__all__ = [
    "Agent", "Batch", "Board", "BoardError", "Bundle", "BundleError", "Change", "Counterexample", "Counters",
    "Error", "Fact", "Finding", "FindingsError", "Fired", "Outcome", "Place", "Program", "PropertyResult",
    "ReadError", "RecordingError", "Reloaded", "Report", "SituSyntaxError", "Step", "TestResult", "TrustError",
    "Value", "Why", "WriteError", "build", "check", "fmt", "load", "load_path", "load_text", "test",
]


def _is_source(rules: PathLike) -> bool:
    """A ``str`` with a line break or a brace is rules' text; anything
    else names a file."""
    return isinstance(rules, str) and ("\n" in rules or "{" in rules)


def check(path_or_source: PathLike, *, name: str = "<source>") -> list[Finding]:
    """Checks rules (a file, with its includes, or a source text) and
    returns every finding, errors and warnings, with its place. Raises
    :class:`ReadError` only when the file cannot be read."""
    if _is_source(path_or_source):
        text = _situ.check(text=str(path_or_source), name=name)
    else:
        text = _situ.check(path=os.fspath(path_or_source))
    return [Finding.from_json(f) for f in json.loads(text)]


def fmt(source: str) -> str:
    """The source in situ's one canonical layout. Raises
    :class:`SituSyntaxError` (with its findings) on syntax errors."""
    return _situ.format(source)


def build(
    path_or_source: PathLike,
    *,
    key: Optional[PathLike] = None,
    binary: bool = False,
    deny_warnings: bool = False,
    name: str = "<source>",
) -> Bundle:
    """Builds rules to a bundle (JSON, or binary), signed with the secret
    key file ``key`` if given. Raises :class:`FindingsError` on rules with
    errors (or warnings, when denied)."""
    k = os.fspath(key) if key is not None else None
    if _is_source(path_or_source):
        return _situ.build(text=str(path_or_source), name=name, key=k, binary=binary, deny_warnings=deny_warnings)
    return _situ.build(path=os.fspath(path_or_source), key=k, binary=binary, deny_warnings=deny_warnings)


def _keys(trust: Optional[Sequence[PathLike]]) -> Optional[list[str]]:
    if trust is None:
        return None
    if isinstance(trust, (str, os.PathLike)):
        return [os.fspath(trust)]
    return [os.fspath(k) for k in trust]


def load(bundle: Union[Bundle, bytes], *, trust: Optional[Sequence[PathLike]] = None) -> Program:
    """Loads a bundle (a :class:`Bundle` or its bytes). With ``trust`` (public
    key files) only a bundle signed by one of them loads
    (:class:`TrustError`); a damaged one never does (:class:`BundleError`)."""
    data = bundle.data if isinstance(bundle, Bundle) else bytes(bundle)
    return _situ.load(data, trust=_keys(trust))


def load_path(
    path: PathLike, *, trust: Optional[Sequence[PathLike]] = None, deny_warnings: bool = False
) -> Program:
    """Loads a ``.situ`` file (checked and compiled: :class:`FindingsError`)
    or a bundle file (verified under ``trust``). Under a trust policy a
    source is refused: it carries no signature."""
    return _situ.load_path(os.fspath(path), trust=_keys(trust), deny_warnings=deny_warnings)


def load_text(source: str, *, name: str = "<source>", deny_warnings: bool = False) -> Program:
    """Loads rules from a source text (checked and compiled)."""
    return _situ.load_text(source, name=name, deny_warnings=deny_warnings)


def _program_of(rules: object, trust: Optional[Sequence[PathLike]]) -> Program:
    """What `Board(rules)` runs: a program from a bundle, its bytes, a path
    to a source or a bundle, or a source text."""
    if isinstance(rules, (Bundle, bytes, bytearray, memoryview)):
        return load(rules if isinstance(rules, Bundle) else bytes(rules), trust=trust)
    if isinstance(rules, str) and _is_source(rules):
        if trust is not None:
            raise TrustError("a source text carries no signature: give a signed bundle under a trust policy", "trust")
        return load_text(rules)
    if isinstance(rules, (str, os.PathLike)):
        return load_path(rules, trust=trust)
    raise Error(f"a board runs a Program, a Bundle, bytes, a path or a source text, not {type(rules).__name__}", "usage")


def test(
    *paths: PathLike,
    filter: Optional[str] = None,
    allow_undecided: bool = False,
    effort: Optional[int] = None,
    max_states: Optional[int] = None,
    depth: Optional[int] = None,
    cases: Optional[int] = None,
    length: Optional[int] = None,
    seed: Optional[int] = None,
) -> Report:
    """Runs every ``test`` block and checks every property of the files, as
    ``situ test`` does: each property proved, violated or undecided (never
    passed for "not found"). ``effort`` is IC3's work budget per property
    (SAT propagations): the same budget gives the same verdict anywhere;
    ``depth`` and ``max_states`` bound the exhaustive search, ``cases``,
    ``length`` and ``seed`` the random one. Raises :class:`ReadError` when
    a file cannot be read; rules with errors are in ``Report.findings``."""
    records, verdict = _situ.test(
        [os.fspath(p) for p in paths],
        filter=filter,
        allow_undecided=allow_undecided,
        effort=effort,
        max_states=max_states,
        depth=depth,
        cases=cases,
        length=length,
        seed=seed,
    )
    return report_of(json.loads(records), verdict)
