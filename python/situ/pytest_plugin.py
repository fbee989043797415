"""The pytest plugin of situ (entry point ``pytest11``): ``pytest`` in a
folder of ``.situ`` files collects every ``test`` block and every
``property`` as an item, at its file and line. A test that fails shows its
failures; a violated property shows its counterexample and the ``test``
block that replays it; an undecided property fails unless it is marked
``@pytest.mark.situ_undecided_ok`` (in ``pytest.ini``:
``situ_allow_undecided = true`` allows them all).

Each file's suite runs once, with the library's verdict policy (the same
as ``situ test``); ``--situ-effort N`` sets IC3's work budget,
``--situ-depth``, ``--situ-cases``, ``--situ-length`` and ``--situ-seed``
the searches'.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any, Iterator, Optional, Union

import pytest

import situ

from .findings import PropertyResult, Report, TestResult


def pytest_addoption(parser: pytest.Parser) -> None:
    group = parser.getgroup("situ")
    group.addoption(
        "--situ-effort",
        type=int,
        default=None,
        help="IC3's work budget per property (SAT propagations); the default is situ test's",
    )
    group.addoption("--situ-depth", type=int, default=None, help="the most events the exhaustive search goes")
    group.addoption("--situ-cases", type=int, default=None, help="random runs per property")
    group.addoption("--situ-length", type=int, default=None, help="events per random run")
    group.addoption("--situ-seed", type=int, default=None, help="the seed of the random search")
    parser.addini("situ_allow_undecided", "undecided properties pass", type="bool", default=False)


def pytest_configure(config: pytest.Config) -> None:
    config.addinivalue_line("markers", "situ_undecided_ok: an undecided property of this item does not fail")
    config.addinivalue_line("markers", "situ: a test or property of a .situ file")
    config.option.keyword = _phrase(config.option.keyword)


def _phrase(keyword: str) -> str:
    """Blocks are named in words (``"low battery sends it home"``), which
    ``-k`` cannot parse: a ``-k`` of plain words that is not an expression
    selects the items whose name holds every word (``low and battery``)."""
    words = keyword.split()
    if len(words) < 2 or not all(w.replace("_", "").isalnum() for w in words):
        return keyword
    if any(w in ("and", "or", "not") for w in words):
        return keyword
    return " and ".join(words)


def pytest_collect_file(parent: pytest.Collector, file_path: Path) -> Optional[pytest.Collector]:
    if file_path.suffix == ".situ":
        return SituFile.from_parent(parent, path=file_path)
    return None


class SituFailure(Exception):
    """A test or property of a rules file that did not pass."""


class SituFile(pytest.File):
    """A rules file: its ``test`` and ``property`` blocks (those written in
    it, not in the files it includes)."""

    _report: Optional[Report] = None

    def collect(self) -> Iterator[pytest.Item]:
        try:
            blocks = situ._situ.blocks(str(self.path))
        except situ.FindingsError as e:
            yield SituErrors.from_parent(self, name="check", error=e)
            return
        here = self.path.resolve()
        for kind, name, file, line in blocks:
            if Path(file).resolve() != here:
                continue
            yield SituItem.from_parent(self, name=name, kind=kind, line=line)

    def report(self) -> Report:
        if self._report is None:
            opt = self.config.getoption
            self._report = situ.test(
                self.path,
                effort=opt("situ_effort"),
                depth=opt("situ_depth"),
                cases=opt("situ_cases"),
                length=opt("situ_length"),
                seed=opt("situ_seed"),
                allow_undecided=True,
            )
        return self._report


class SituErrors(pytest.Item):
    """A rules file with errors: one failing item with its findings."""

    def __init__(self, *, error: situ.FindingsError, **kwargs: Any) -> None:
        super().__init__(**kwargs)
        self.error = error

    def runtest(self) -> None:
        raise SituFailure("\n".join(str(f) for f in self.error.findings))

    def repr_failure(self, excinfo: pytest.ExceptionInfo[BaseException], style: Any = None) -> str:
        return str(excinfo.value)

    def reportinfo(self) -> tuple[Union[Path, str], Optional[int], str]:
        return self.path, 0, f"{self.path.name}: errors"


class SituItem(pytest.Item):
    """One ``test`` or ``property`` block."""

    def __init__(self, *, kind: str, line: int, **kwargs: Any) -> None:
        super().__init__(**kwargs)
        self.kind = kind
        self.line = line
        self.add_marker(pytest.mark.situ)

    def _result(self) -> Union[TestResult, PropertyResult]:
        parent = self.parent
        assert isinstance(parent, SituFile)
        report = parent.report()
        found: list[Union[TestResult, PropertyResult]] = list(report.tests if self.kind == "test" else report.properties)
        for r in found:
            if r.name == self.name and r.line == self.line:
                return r
        raise SituFailure(f"situ test did not report the {self.kind} \"{self.name}\"")

    def runtest(self) -> None:
        r = self._result()
        if isinstance(r, TestResult):
            if not r.passed:
                raise SituFailure("\n".join(r.failures) or "the test failed")
            return
        allowed = self.get_closest_marker("situ_undecided_ok") is not None or bool(
            self.config.getini("situ_allow_undecided")
        )
        if r.verdict == "proved":
            return
        if r.verdict == "undecided":
            if allowed:
                pytest.skip("undecided (allowed): " + "; ".join(r.because))
            raise SituFailure(
                "undecided: no checker proved or broke it within its budget\n  " + "\n  ".join(r.because)
            )
        if r.counterexample is not None:
            c = r.counterexample
            lines = [f"violated ({c.found_by}, {len(c.events)} events): {c.reason}"]
            lines += [f"  {s.event} at {s.time_ns / 1e6:g}ms -> {s.state}" for s in c.events]
            lines += ["replay it as a test (paste it into the file):", c.test]
            raise SituFailure("\n".join(lines))
        raise SituFailure(f"{r.verdict}: " + "; ".join(r.because))

    def repr_failure(self, excinfo: pytest.ExceptionInfo[BaseException], style: Any = None) -> str:
        if isinstance(excinfo.value, SituFailure):
            return f"{self.kind} \"{self.name}\" ({self.path.name}:{self.line})\n{excinfo.value}"
        return str(super().repr_failure(excinfo))

    def reportinfo(self) -> tuple[Union[Path, str], Optional[int], str]:
        return self.path, self.line - 1, f"{self.kind} \"{self.name}\""
