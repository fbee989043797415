"""The embedded board: the running stack's admission rule, answers as
data, callbacks, batches, reloads, and every bad input a typed error."""

from __future__ import annotations

import math
import time
from pathlib import Path

import pytest

import situ


def test_an_order_starts_a_pick_and_why_names_rule_line_and_facts(board: situ.Board) -> None:
    assert board.state == "IDLE" and board.why() is None
    board.post("BATT", at=0, charge=80.0)
    out = board.post("Scanner.ORDER", at=0.01, item=7)
    assert out.accepted and out.change is not None
    assert (out.change.previous, out.change.state, out.change.rules) == ("IDLE", "PICKING", ["order"])
    why = board.why()
    assert why is not None and why.state == "PICKING"
    [fired] = why.firings
    assert (fired.rule, fired.line) == ("order", 49) and fired.file.endswith("picker.situ")
    assert [(f.agent, f.event, f.fields) for f in fired.facts] == [
        ("Scanner", "ORDER", {"item": 7}),
        ("Battery", "BATT", {"charge": 80.0}),
    ]
    arm = {a.name: a for a in board.agents()}["Arm"]
    assert (arm.mode, arm.function, arm.reads_from, arm.sends_to) == ("running", "reach", ["Scanner"], ["Gripper"])


def test_late_and_sleeping_agents_events_are_not_taken_and_counted(board: situ.Board) -> None:
    board.post("BATT", at=0.1, charge=50.0)
    late = board.post("BATT", at=0.05, charge=5.0)
    assert not late and late.key == "out of order"
    assert board.state == "IDLE"
    board.post("BATT", at=0.2, charge=10.0)
    assert board.state == "CHARGING"
    asleep = board.post("PICKED", at=0.3)
    assert asleep.key == "sleeping" and asleep.reason is not None and "`Arm` sleeps in CHARGING" in asleep.reason
    assert board.counters().not_taken == {"out of order": 1, "sleeping": 1}


def test_the_system_clock_refuses_events_from_the_future(picker: situ.Program) -> None:
    b = situ.Board(picker, clock="system")
    assert b.post("BATT", at=time.time() + 3600, charge=50.0).key == "from the future"
    assert b.post("BATT", charge=50.0).accepted
    assert abs(b.now - time.time()) < 60


def test_nan_is_taken_and_matches_nothing(board: situ.Board) -> None:
    assert board.post("BATT", at=0, charge=math.nan).accepted
    board.post("ORDER", at=0, item=1)
    assert board.state == "IDLE"
    [batt] = [f for f in board.facts() if f.agent == "Battery"]
    assert math.isnan(float(batt.fields["charge"]))


def test_time_passing_makes_a_silent_agent_stale(board: situ.Board) -> None:
    board.post("BATT", at=0, charge=80.0)
    board.post("ORDER", at=0, item=3)
    assert board.advance(2.0) is None
    change = board.advance(3.5)
    assert change is not None and (change.state, change.rules) == ("FAULT", ["battery_silent"])
    assert [f.agent for f in board.facts() if f.stale] == ["Battery"]


def test_on_change_sees_every_change_in_order_and_post_many_batches(board: situ.Board) -> None:
    seen: list[tuple[str, str]] = []
    board.on_change(lambda c: seen.append((c.previous, c.state)))
    batch = board.post_many(
        [
            ("BATT", 0.1, {"charge": 80.0}),
            ("ORDER", 0.1, {"item": 2}),
            ("BATT", 0.05, {"charge": 1.0}),
            ("PICKED", 0.2, None),
            ("OBST", 0.3, {"distance": 0.1, "side": "left"}),
        ]
    )
    assert (batch.accepted, batch.not_taken) == (4, {"out of order": 1})
    assert [(c.previous, c.state) for _, c in batch.changes] == seen
    assert [i for i, _ in batch.changes] == [1, 3, 4]
    assert seen == [("IDLE", "PICKING"), ("PICKING", "CARRYING"), ("CARRYING", "FAULT")]


def test_an_exception_in_a_callback_propagates_and_the_event_stays_taken(board: situ.Board) -> None:
    def boom(c: situ.Change) -> None:
        raise KeyError(c.state)

    board.on_change(boom)
    board.post("BATT", at=0, charge=80.0)
    with pytest.raises(KeyError):
        board.post("ORDER", at=0, item=1)
    assert board.state == "PICKING"


def test_the_fsm_follows_its_agents_events(board: situ.Board) -> None:
    def gripper() -> situ.Agent:
        return {a.name: a for a in board.agents()}["Gripper"]

    assert (gripper().mode, gripper().fsm_state) == ("waiting", "Open")
    board.post("SUCKED", at=0)
    assert (gripper().mode, gripper().fsm_state) == ("running", "Holding")


@pytest.mark.parametrize(
    "event, fields, code",
    [
        ("BAT", {"charge": 1.0}, "unknown-event"),
        ("Lidar.BATT", {"charge": 1.0}, "not-its-agent"),
        ("NoSuchAgent.BATT", {"charge": 1.0}, "not-its-agent"),
        ("BATT", {}, "missing-fields"),
        ("BATT", {"charge": "full"}, "field-type"),
        ("BATT", {"charge": [1]}, "field-type"),
        ("ORDER", {"item": 1.5}, "field-type"),
        ("ORDER", {"item": True}, "field-type"),
        ("ORDER", {"item": 2**70}, "field-type"),
        ("OBST", {"distance": 1.0, "side": "up"}, "field-type"),
        ("BATT", {"charge": 1.0, "volts": 3.0}, "unknown-field"),
    ],
)
def test_a_wrong_event_field_or_value_is_a_board_error(
    board: situ.Board, event: str, fields: dict[str, situ.Value], code: str
) -> None:
    with pytest.raises(situ.BoardError) as e:
        board.post(event, at=0, payload=fields)
    assert e.value.code == code, str(e.value)
    assert board.counters().accepted == 0 and board.state == "IDLE"


@pytest.mark.parametrize("at", [-1, -0.5, math.nan, math.inf, True])
def test_a_time_that_is_not_one_is_a_board_error(board: situ.Board, at: float) -> None:
    with pytest.raises(situ.BoardError) as e:
        board.post("BATT", at=at, charge=1.0)
    assert e.value.code == "bad-time"


def test_an_unknown_event_suggests_the_nearest(board: situ.Board) -> None:
    with pytest.raises(situ.BoardError, match="did you mean `BATT`"):
        board.post("BAT", charge=1.0)


def test_reload_keeps_the_state_and_facts_and_refuses_rules_without_the_state(
    board: situ.Board, picker_text: str
) -> None:
    board.post("BATT", at=0, charge=80.0)
    board.post("ORDER", at=0, item=3)
    stricter = situ.load_text(picker_text.replace("BATT(charge < 20.0)", "BATT(charge < 90.0)"))
    r = board.reload(stricter)
    assert "Battery" in r.carried
    assert r.change is not None and (r.change.previous, r.change.state) == ("PICKING", "CHARGING")
    with pytest.raises(situ.BoardError) as e:
        board.reload(situ.load_text("states { A initial }\nagent X sensor { event E }\n"))
    assert e.value.code == "reload" and board.state == "CHARGING"


def test_a_bad_clock_is_an_error(picker: situ.Program) -> None:
    with pytest.raises(situ.Error):
        situ.Board(picker, clock="sundial")


def test_a_callback_may_read_the_board_and_another_thread_may_post(board: situ.Board) -> None:
    import threading

    modes: list[str] = []
    board.on_change(lambda c: modes.append({a.name: a.mode for a in board.agents()}["Arm"] + " in " + board.state))
    board.post("BATT", at=0, charge=80.0)
    t = threading.Thread(target=lambda: board.post("ORDER", at=0, item=1))
    t.start()
    t.join()
    assert modes == ["running in PICKING"]


def test_with_missions_a_final_state_starts_a_new_mission(picker: situ.Program) -> None:
    b = situ.Board(picker, missions=True)
    b.post("BATT", at=0, charge=80.0)
    b.post("ORDER", at=0, item=1)
    b.post("OBST", at=0.1, distance=0.1, side="right")
    assert b.state == "FAULT" and "FAULT" in picker.final_states
    b.post("BATT", at=0.2, charge=80.0)
    assert b.state == "IDLE" and b.counters().missions == 1
    # Without, FAULT stays.
    plain = situ.Board(picker)
    steps: list[tuple[str, float, dict[str, situ.Value]]] = [
        ("BATT", 0, {"charge": 80.0}),
        ("ORDER", 0, {"item": 1}),
        ("OBST", 0.1, {"distance": 0.1, "side": "right"}),
    ]
    for e, at, p in steps:
        plain.post(e, at=at, payload=p)
    plain.post("BATT", at=0.2, charge=80.0)
    assert plain.state == "FAULT"
    plain.reset()
    assert plain.state == "IDLE" and plain.facts() == []


def test_a_board_runs_a_program_a_bundle_bytes_a_path_or_a_source(picker_text: str, tmp_path: Path) -> None:
    from conftest import PICKER

    bundle = situ.build(picker_text)
    f = tmp_path / "picker.bundle"
    bundle.save(str(f))
    for rules in (situ.load_text(picker_text), bundle, bundle.data, PICKER, str(PICKER), f, picker_text):
        b = situ.Board(rules)
        b.post("BATT", at=0, charge=80.0)
        b.post("ORDER", at=0, item=1)
        assert b.state == "PICKING", rules
    with pytest.raises(situ.Error):
        situ.Board(42)  # type: ignore[arg-type]
    with pytest.raises(situ.TrustError):
        situ.Board(picker_text, trust=[str(tmp_path / "k.pub")])


def test_a_board_whose_agents_are_not_situs_takes_a_sleeping_agents_events(picker: situ.Program) -> None:
    b = situ.Board(picker, sleeping="take")
    b.post("BATT", at=0.2, charge=10.0)
    assert b.state == "CHARGING"
    assert b.post("PICKED", at=0.3).accepted
    with pytest.raises(situ.Error):
        situ.Board(picker, sleeping="snooze")


def test_post_many_takes_ids_and_values_in_field_order(picker: situ.Program) -> None:
    named = situ.Board(picker)
    fast = situ.Board(picker)
    batt, order, obst = (fast.event_id(e) for e in ("BATT", "Scanner.ORDER", "OBST"))
    a = named.post_many([("BATT", 0.0, {"charge": 80.0}), ("ORDER", 0.1, {"item": 2}), ("OBST", 0.2, {"distance": 0.1, "side": "left"})])
    b = fast.post_many_ids([(batt, 0.0, (80.0,)), (order, 0.1, (2,)), (obst, 0.2, (0.1, "left"))])
    assert [(i, c.state) for i, c in a.changes] == [(i, c.state) for i, c in b.changes] == [(1, "PICKING"), (2, "FAULT")]
    for bad, code in [((obst, 0.3, (0.1,)), "missing-fields"), ((obst, 0.3, (0.1, "up")), "field-type"),
                      ((batt, 0.3, (1.0, 2.0)), "unknown-field"), ((99, 0.3, ()), "unknown-event")]:
        with pytest.raises(situ.BoardError) as e:
            fast.post_many_ids([bad])
        assert e.value.code == code, (bad, str(e.value))
    with pytest.raises(situ.BoardError):
        fast.event_id("NOPE")
