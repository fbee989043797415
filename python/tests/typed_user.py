"""A user's program that calls every public function of the package; it is
type-checked with `mypy --strict` (scripts/test.sh) and run by
test_typed_user.py, so the stubs cannot drift from what the module does."""

from __future__ import annotations

import os
import sys
import tempfile
from pathlib import Path
from typing import Optional

import situ


def main(rules: Path, public_key: Optional[Path] = None, secret_key: Optional[Path] = None) -> int:
    findings: list[situ.Finding] = situ.check(rules)
    errors = [f for f in findings if f.severity == "error"]
    text: str = situ.fmt(rules.read_text())
    bundle: situ.Bundle = situ.build(text, key=secret_key, binary=True)
    with tempfile.TemporaryDirectory() as d:
        bundle.save(os.path.join(d, "rules.bundle"))
    trust = [public_key] if public_key is not None else None
    program: situ.Program = situ.load(bundle, trust=trust)
    also: situ.Program = situ.load_path(rules)
    again: situ.Program = situ.load_text(text, name="again.situ")
    print(program.states, program.initial, program.agents, program.events, program.rules, program.signed_by)
    print(also.fields(also.events[0]), again.initial)
    board = situ.Board(program, clock="manual", max_skew=0.5)
    changes: list[situ.Change] = []
    board.on_change(changes.append)
    def some(ty: str) -> situ.Value:
        return {"f64": 1.0, "i64": 1, "bool": True}.get(ty, ty.strip("{}").split(",")[0])

    first = program.events[0]
    payload: dict[str, situ.Value] = {name: some(ty) for name, ty in program.fields(first)}
    out: situ.Outcome = board.post(first, at=0.0, payload=payload)
    if not out.accepted:
        print(out.key, out.reason)
    batch: situ.Batch = board.post_many([(first, 0.1, payload)])
    print(batch.accepted, batch.not_taken, [c.state for _, c in batch.changes])
    change: Optional[situ.Change] = board.advance(1.0)
    why: Optional[situ.Why] = board.why()
    if why is not None:
        for fired in why.firings:
            print(fired.rule, fired.file, fired.line, [(f.agent, f.event, f.fields) for f in fired.facts])
    for agent in board.agents():
        print(agent.name, agent.mode, agent.function, agent.reads_from, agent.sends_to, agent.fsm_state)
    for fact in board.facts():
        print(fact.agent, fact.event, fact.time, fact.stale, fact.fields)
    counters: situ.Counters = board.counters()
    reloaded: situ.Reloaded = board.reload(also)
    print(change, counters.accepted, reloaded.carried, board.state, board.now)
    report: situ.Report = situ.test(rules, effort=1_000_000)
    for p in report.properties:
        cex: Optional[situ.Counterexample] = p.counterexample
        print(p.name, p.verdict, p.proved_by, p.because, cex.test if cex else None)
    for t in report.tests:
        print(t.name, t.passed, t.failures)
    try:
        board.post("NO_SUCH_EVENT")
    except situ.BoardError as e:
        print(e.code, e.message)
    try:
        situ.build("states { A initial }\nrule r { when state == A and X then A }\n")
    except situ.FindingsError as e:
        print(e.code, [str(f) for f in e.findings])
    return 1 if errors or not report.ok else 0


if __name__ == "__main__":
    sys.exit(main(Path(sys.argv[1])))
