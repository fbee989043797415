"""situ.test: the three verdicts, counterexamples as data and as a test
block that replays."""

from __future__ import annotations

from pathlib import Path

import situ

VIOLATED = """
property "a pick never ends in a fault" {
    always (state == PICKING -> next state != FAULT)
}
"""


def ladder() -> str:
    s = "states { S0 initial " + " ".join(f"S{i}" for i in range(1, 15)) + " }\n"
    s += "agent Up sensor { " + " ".join(f"event U{i}" for i in range(1, 15)) + " }\n"
    s += "agent Noise sensor { event HUM event BUZZ }\n"
    for i in range(1, 15):
        s += f"rule r{i} {{ when state == S{i - 1} and U{i} then S{i} }}\n"
    return s + 'property "the top is never reached" { never state == S14 }\n'


def test_proved_properties_and_passing_tests_pass(picker_text: str, tmp_path: Path) -> None:
    f = tmp_path / "picker.situ"
    f.write_text(picker_text)
    r = situ.test(f)
    assert r.ok and (r.passed, r.failed, r.undecided) == (2, 0, 0)
    [p] = r.properties
    assert p.verdict == "proved" and p.proved_by and not p.vacuous


def test_a_violated_property_has_a_counterexample_that_replays(picker_text: str, tmp_path: Path) -> None:
    f = tmp_path / "picker.situ"
    f.write_text(picker_text + VIOLATED)
    r = situ.test(f)
    assert not r.ok
    [p] = [p for p in r.properties if p.verdict != "proved"]
    assert p.verdict == "violated" and p.counterexample is not None
    c = p.counterexample
    assert c.events[-1].state == "FAULT"
    assert c.test.startswith("test ")
    # The replay block parses where it is pasted and passes: it expects
    # what the counterexample says.
    replay = tmp_path / "replay.situ"
    replay.write_text('include "picker.situ"\n' + c.test.replace(p.name, "replay"))
    again = situ.test(replay, filter="replay")
    assert [t.passed for t in again.tests] == [True], again


def test_a_deep_false_property_at_a_tiny_budget_is_undecided_never_ok(tmp_path: Path) -> None:
    f = tmp_path / "ladder.situ"
    f.write_text(ladder())
    r = situ.test(f, effort=0, depth=2, cases=1, length=3)
    [p] = r.properties
    assert p.verdict == "undecided" and any("budget" in b for b in p.because), p
    assert (r.undecided, r.verdict) == (1, "fail")
    assert situ.test(f, effort=0, depth=2, cases=1, length=3, allow_undecided=True).verdict == "pass"


def test_rules_with_errors_are_findings_of_the_report(tmp_path: Path) -> None:
    f = tmp_path / "bad.situ"
    f.write_text("states { A initial }\nrule r { when state == A and NOPE then A }\n")
    r = situ.test(f)
    assert not r.ok and [x.code for x in r.findings if x.severity == "error"]
