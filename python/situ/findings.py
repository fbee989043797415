"""Findings of a check and reports of a test suite, as typed data."""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any, Optional


@dataclass(frozen=True)
class Place:
    file: str
    line: int
    column: int
    end_line: int
    end_column: int
    label: str = ""


@dataclass(frozen=True)
class Finding:
    """One finding of ``situ check``: its code (``E0104``), severity
    (``error`` or ``warning``), message, place, help, related places and
    the compiler's witness (the run or values that show it), as data."""

    code: str
    severity: str
    message: str
    file: str
    line: int
    column: int
    end_line: int
    end_column: int
    label: str
    help: Optional[str]
    related: list[Place]
    witness: Any
    allowed: bool

    @staticmethod
    def from_json(o: dict[str, Any]) -> "Finding":
        code = str(o.get("code", ""))
        return Finding(
            code=code[len("situ::"):] if code.startswith("situ::") else code,
            severity=str(o.get("severity", "")),
            message=str(o.get("message", "")),
            file=str(o.get("file", "")),
            line=int(o.get("line", 0)),
            column=int(o.get("column", 0)),
            end_line=int(o.get("end_line", 0)),
            end_column=int(o.get("end_column", 0)),
            label=str(o.get("label", "")),
            help=o.get("help"),
            related=[Place(**r) for r in o.get("related", [])],
            witness=o.get("witness"),
            allowed=bool(o.get("allowed", False)),
        )

    def __str__(self) -> str:
        return f"{self.file}:{self.line}:{self.column}: {self.severity}[{self.code}]: {self.message}"


@dataclass(frozen=True)
class Step:
    """One event of a run: the event as written in a test, its time (ns),
    the state after it and the rules that fired."""

    event: str
    time_ns: int
    state: str
    fired: list[str]


@dataclass(frozen=True)
class Counterexample:
    found_by: str
    events: list[Step]
    reason: str
    #: The run as a ``test`` block that replays it (paste it into the file).
    test: str


@dataclass(frozen=True)
class TestResult:
    """A ``test`` block: it passes or fails."""

    __test__ = False  # not a pytest class

    name: str
    file: str
    line: int
    passed: bool
    events: int
    failures: list[str]


@dataclass(frozen=True)
class PropertyResult:
    """A property: ``proved`` (``proved_by`` names the checker),
    ``violated`` (with a ``counterexample``), ``undecided`` (``because``
    says what each checker reached) or ``disagree`` (an error of situ)."""

    name: str
    file: str
    line: int
    verdict: str
    proved_by: Optional[str]
    because: list[str]
    counterexample: Optional[Counterexample]
    #: The premise of an implication never holds: the property says nothing.
    vacuous: bool
    checkers: dict[str, str] = field(default_factory=dict)

    @property
    def passed(self) -> bool:
        return self.verdict == "proved"


@dataclass(frozen=True)
class Report:
    """A suite's tests and properties, its counts and its verdict: it
    passes when every test passed and every property was proved (undecided
    ones fail it unless allowed)."""

    tests: list[TestResult]
    properties: list[PropertyResult]
    findings: list[Finding]
    passed: int
    failed: int
    undecided: int
    verdict: str

    @property
    def ok(self) -> bool:
        return self.verdict == "pass"


def _line(place: str) -> int:
    # "file.situ:12:5"
    parts = place.rsplit(":", 2)
    try:
        return int(parts[-2]) if len(parts) == 3 else 0
    except ValueError:
        return 0


def report_of(records: list[dict[str, Any]], verdict: str) -> Report:
    tests: list[TestResult] = []
    props: list[PropertyResult] = []
    findings: list[Finding] = []
    summary: dict[str, Any] = {}
    for r in records:
        kind = r.get("kind")
        if kind == "test":
            tests.append(
                TestResult(
                    name=r["name"],
                    file=r["file"],
                    line=_line(r["place"]),
                    passed=bool(r["passed"]),
                    events=int(r["events"]),
                    failures=[f"{f['place']}: {f['message']}" for f in r["failures"]],
                )
            )
        elif kind == "property":
            c = r.get("counterexample")
            cex = None
            if c is not None:
                cex = Counterexample(
                    found_by=c["found_by"],
                    events=[Step(e["event"], int(e["time_ns"]), e["state"], list(e["fired"])) for e in c["events"]],
                    reason=str(c.get("reason", "")),
                    test=c["test"],
                )
            premise = r.get("premise") or {}
            checkers = {k: r[k]["summary"] for k in ("exhaustive", "symbolic", "random") if r.get(k)}
            props.append(
                PropertyResult(
                    name=r["name"],
                    file=r["file"],
                    line=_line(r["place"]),
                    verdict=r["verdict"],
                    proved_by=r.get("proved_by"),
                    because=list(r.get("undecided_because") or []),
                    counterexample=cex,
                    vacuous=bool(premise.get("vacuous", False)),
                    checkers=checkers,
                )
            )
        elif kind == "summary":
            summary = r
        else:
            findings.append(Finding.from_json(r))
    return Report(
        tests=tests,
        properties=props,
        findings=findings,
        passed=int(summary.get("passed", 0)),
        failed=int(summary.get("failed", 0)),
        undecided=int(summary.get("undecided", 0)),
        verdict=verdict,
    )
