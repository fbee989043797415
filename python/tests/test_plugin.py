"""The pytest plugin, run by pytest itself (pytester) on folders of .situ
files: items with their file and line, counterexamples as failure text,
undecided properties failing unless marked, -k by the blocks' words."""

from __future__ import annotations

import pytest

import situ

from test_report import VIOLATED, ladder

MOWER_TEST = 'test "low battery sends it home" {'


@pytest.fixture
def folder(pytester: pytest.Pytester, picker_text: str) -> pytest.Pytester:
    from conftest import ROOT

    pytester.makefile(".situ", picker=picker_text, mower=(ROOT / "examples" / "mower" / "mower.situ").read_text())
    return pytester


def test_every_test_block_and_property_is_an_item(folder: pytest.Pytester) -> None:
    r = folder.runpytest("-v")
    r.assert_outcomes(passed=4)
    r.stdout.fnmatch_lines(
        [
            "*mower.situ::low battery sends it home PASSED*",
            "*mower.situ::a fault is never left PASSED*",
            "*picker.situ::an order starts a pick PASSED*",
            "*picker.situ::a fault is never left PASSED*",
        ]
    )


def test_k_selects_by_the_blocks_words(folder: pytest.Pytester) -> None:
    r = folder.runpytest("-v", "-k", "low battery")
    r.assert_outcomes(passed=1, deselected=3)
    r.stdout.fnmatch_lines(["*low battery sends it home PASSED*"])
    folder.runpytest("-k", "fault and not mower").assert_outcomes(passed=1, deselected=3)


def test_a_violated_property_fails_with_its_counterexample(pytester: pytest.Pytester, picker_text: str) -> None:
    pytester.makefile(".situ", picker=picker_text + VIOLATED)
    r = pytester.runpytest()
    r.assert_outcomes(passed=2, failed=1)
    r.stdout.fnmatch_lines(
        [
            '*property "a pick never ends in a fault" (picker.situ:*)*',
            "*violated (*",
            "*replay it as a test*",
            'test "counterexample: a pick never ends in a fault" {*',
        ]
    )


def test_a_failing_test_block_shows_its_failures(pytester: pytest.Pytester, picker_text: str) -> None:
    wrong = '\ntest "a wrong expectation" {\n    on BATT(charge: 80.0)\n    expect state FAULT\n}\n'
    pytester.makefile(".situ", picker=picker_text + wrong)
    r = pytester.runpytest()
    r.assert_outcomes(passed=2, failed=1)
    r.stdout.fnmatch_lines(['*test "a wrong expectation"*', "*FAULT*"])


def test_an_undecided_property_fails_unless_allowed(pytester: pytest.Pytester) -> None:
    pytester.makefile(".situ", ladder=ladder())
    # Tiny budgets: IC3 gives up, the searches are cut short.
    tiny = ["--situ-effort", "0", "--situ-depth", "2", "--situ-cases", "1", "--situ-length", "3"]
    r = pytester.runpytest(*tiny)
    r.assert_outcomes(failed=1)
    r.stdout.fnmatch_lines(["*undecided: no checker proved or broke it*"])
    pytester.makeini("[pytest]\nsitu_allow_undecided = true\n")
    pytester.runpytest(*tiny).assert_outcomes(skipped=1)
    # With enough work the property is broken: the budget decides, not the clock.
    pytester.runpytest().assert_outcomes(failed=1)


def test_a_marked_item_may_be_undecided(pytester: pytest.Pytester) -> None:
    pytester.makefile(".situ", ladder=ladder())
    pytester.makeconftest(
        "import pytest\n"
        "def pytest_collection_modifyitems(items):\n"
        "    for item in items:\n"
        "        item.add_marker(pytest.mark.situ_undecided_ok)\n"
    )
    tiny = ["--situ-effort", "0", "--situ-depth", "2", "--situ-cases", "1", "--situ-length", "3"]
    pytester.runpytest(*tiny).assert_outcomes(skipped=1)


def test_rules_with_errors_are_one_failing_item(pytester: pytest.Pytester) -> None:
    pytester.makefile(".situ", broken="states { A initial }\nrule r { when state == A and NOPE then A }\n")
    r = pytester.runpytest()
    r.assert_outcomes(failed=1)
    r.stdout.fnmatch_lines(["*E0104*NOPE*"])


def test_the_drones_blocks_are_collected_with_their_lines(pytester: pytest.Pytester) -> None:
    from conftest import ROOT

    drone = (ROOT / "tests" / "explore" / "inspection-drone.situ").read_text()
    mower = (ROOT / "examples" / "mower" / "mower.situ").read_text()
    pytester.makefile(".situ", drone=drone, mower=mower)
    r = pytester.runpytest("--collect-only", "-q")
    names = [line for line in r.outlines if "::" in line]
    expected = [b for b in situ._situ.blocks(str(pytester.path / "drone.situ"))]
    assert len(expected) >= 5
    for kind, name, _, _ in expected:
        assert f"drone.situ::{name}" in names, (kind, name, names)
    assert "mower.situ::low battery sends it home" in names
