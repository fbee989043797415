#!/usr/bin/env python3
"""situ's Python package against clipspy on the same stream of events.

The stream is `bench/vs-clips.sh`'s: `situ bench rules/outdoor.situ
--stream-out` writes it (bench/README.md), with the state sequence situ's
own engine reaches. Then, in this one Python process:

- **clipspy** (CLIPS 6.4 in Python, from PyPI) loads the CLIPS translation
  of the rules (`bench/clips/outdoor.clp`) and its driver
  (`bench/clips/driver.clp`, the benchmark's semantics) and is called once
  per event, as a Python program embeds it: the driver's `post` asserts the
  event's fact, expires stale agents and runs the rules to rest, after a
  new mission when the last one ended (`step`, below);
- **situ** `Board.post` is called once per event (`situ.Board(program,
  missions=True, sleeping="take")`: a final state ends the mission and
  every event is taken whatever its agent's mode, as in `situ bench` and
  CLIPS);
- **situ** `Board.post_many` takes the whole stream in one call.

Each engine's state sequence (`INDEX STATE` at every change) must equal
the one `situ bench` wrote, or the script stops with exit 1. The events are
parsed to Python values before the clock starts (for CLIPS too). It prints
one JSON line per engine and the ratios, and `situ bench`'s own figure on
the same stream.

    python3 bench/python/vs_clipspy.py --situ target/release/situ --events 200000
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path
from typing import Any

import clips

import situ

ROOT = Path(__file__).resolve().parents[2]


def read_stream(path: Path) -> list[list[str]]:
    return [line.split() for line in path.read_text().splitlines() if line and not line.startswith("#")]


def situ_events(program: situ.Program, lines: list[list[str]]) -> list[tuple[str, float, dict[str, situ.Value]]]:
    fields: dict[str, list[tuple[str, str]]] = {}
    out: list[tuple[str, float, dict[str, situ.Value]]] = []
    for line in lines:
        t, name, values = int(line[0]), line[1], line[2:]
        fs = fields.get(name)
        if fs is None:
            fs = fields[name] = program.fields(name)
        payload: dict[str, situ.Value] = {}
        for (field, ty), v in zip(fs, values):
            payload[field] = float(v) if ty == "f64" else int(v) if ty == "i64" else (v == "true") if ty == "bool" else v
        out.append((name, t / 1e9, payload))
    return out


def clips_events(lines: list[list[str]]) -> list[list[Any]]:
    def value(v: str) -> Any:
        for conv in (int, float):
            try:
                return conv(v)
            except ValueError:
                pass
        return clips.Symbol(v)

    return [[int(l[0]), clips.Symbol(l[1])] + [value(v) for v in l[2:]] for l in lines]


def run_clips(lines: list[list[str]], states_out: Path) -> dict[str, Any]:
    env = clips.Environment()
    env.load(str(ROOT / "bench" / "clips" / "outdoor.clp"))
    env.load(str(ROOT / "bench" / "clips" / "driver.clp"))
    env.build(
        "(deffunction step (?index ?l)"
        "   (if (or (eq ?*state* GL) (eq ?*state* SP)) then (new-mission))"
        "   (post ?index ?l))"
    )
    env.eval(f'(open "{states_out}" states "w")')
    env.eval("(set-reset-globals FALSE)")
    env.eval("(new-mission)")
    step = env.find_function("step")
    events = clips_events(lines)
    start = time.perf_counter()
    for i, e in enumerate(events):
        step(i, e)
    seconds = time.perf_counter() - start
    env.eval("(close states)")
    return {"engine": "clipspy", "events": len(events), "seconds": seconds, "events_per_sec": len(events) / seconds}


def run_post(program: situ.Program, events: list[tuple[str, float, dict[str, situ.Value]]], states_out: Path) -> dict[str, Any]:
    board = situ.Board(program, missions=True, sleeping="take")
    changes: list[str] = []
    post = board.post
    start = time.perf_counter()
    for i, (name, at, payload) in enumerate(events):
        c = post(name, at, payload).change
        if c is not None:
            changes.append(f"{i} {c.state}")
    seconds = time.perf_counter() - start
    states_out.write_text("".join(s + "\n" for s in changes))
    return {"engine": "situ Board.post", "events": len(events), "seconds": seconds, "events_per_sec": len(events) / seconds}


def run_post_many_ids(
    program: situ.Program, events: list[tuple[str, float, dict[str, situ.Value]]], states_out: Path
) -> dict[str, Any]:
    board = situ.Board(program, missions=True, sleeping="take")
    ids = {name: board.event_id(name) for name in {e[0] for e in events}}
    order = {name: [f for f, _ in program.fields(name)] for name in ids}
    fast = [(ids[n], at, tuple(p[f] for f in order[n])) for n, at, p in events]
    start = time.perf_counter()
    batch = board.post_many_ids(fast)
    seconds = time.perf_counter() - start
    states_out.write_text("".join(f"{i} {c.state}\n" for i, c in batch.changes))
    return {"engine": "situ Board.post_many (ids)", "events": len(events), "seconds": seconds, "events_per_sec": len(events) / seconds}


def run_post_many(
    program: situ.Program, events: list[tuple[str, float, dict[str, situ.Value]]], states_out: Path
) -> dict[str, Any]:
    board = situ.Board(program, missions=True, sleeping="take")
    start = time.perf_counter()
    batch = board.post_many(events)
    seconds = time.perf_counter() - start
    states_out.write_text("".join(f"{i} {c.state}\n" for i, c in batch.changes))
    return {"engine": "situ Board.post_many", "events": len(events), "seconds": seconds, "events_per_sec": len(events) / seconds}


def main() -> int:
    ap = argparse.ArgumentParser(description=(__doc__ or "").splitlines()[0])
    ap.add_argument("--situ", default=str(ROOT / "target" / "release" / "situ"), help="the situ binary")
    ap.add_argument("--events", type=int, default=200_000)
    ap.add_argument("--seed", type=int, default=1)
    args = ap.parse_args()
    rules = ROOT / "rules" / "outdoor.situ"
    with tempfile.TemporaryDirectory() as d:
        work = Path(d)
        stream, reference = work / "stream.events", work / "situ.states"
        bench = subprocess.run(
            [args.situ, "bench", str(rules), "--events", str(args.events), "--seed", str(args.seed),
             "--stream-out", str(stream), "--states-out", str(reference)],
            check=True, capture_output=True, text=True,
        )
        engine = json.loads(bench.stdout)
        lines = read_stream(stream)
        program = situ.load_path(rules)
        events = situ_events(program, lines)
        results = [
            run_clips(lines, work / "clipspy.states"),
            run_post(program, events, work / "post.states"),
            run_post_many(program, events, work / "post_many.states"),
            run_post_many_ids(program, events, work / "post_many_ids.states"),
        ]
        want = reference.read_text()
        for r, f in zip(results, ["clipspy", "post", "post_many", "post_many_ids"]):
            got = (work / f"{f}.states").read_text()
            if got != want:
                a, b = want.splitlines(), got.splitlines()
                first = next((i for i, (x, y) in enumerate(zip(a, b)) if x != y), min(len(a), len(b)))
                print(f"error: {r['engine']} and situ bench reach different states; first difference at line {first + 1}: "
                      f"{a[first] if first < len(a) else 'end'} vs {b[first] if first < len(b) else 'end'}", file=sys.stderr)
                return 1
            r["state_changes"] = len(got.splitlines())
            print(json.dumps(r))
        print(json.dumps({"engine": "situ bench (Rust)", "events": engine["events"], "events_per_sec": engine["events_per_sec"]}))
        print(f"== the {len(results)} engines agree with situ bench: {len(want.splitlines())} state changes", file=sys.stderr)
        clips_rate, post_rate, many_rate, ids_rate = (r["events_per_sec"] for r in results)
        print(f"post/clipspy ratio: {post_rate / clips_rate:.1f}")
        print(f"post_many/clipspy ratio: {many_rate / clips_rate:.1f}")
        print(f"situ bench/post_many ratio: {engine['events_per_sec'] / many_rate:.2f}")
        print(f"situ bench/post_many (ids) ratio: {engine['events_per_sec'] / ids_rate:.2f}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
