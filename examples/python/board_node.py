#!/usr/bin/env python3
"""A robot node in Python with situ's Bulletinboard inside it.

The node loads the rules, embeds a `situ.Board`, feeds it the sensors'
messages and prints the situation as it changes: which state, which rules
decided it, and what each agent now does. The messages come

- from a recording (`--recording run.mcap`, made by `situ run … --record`):
  every event the running stack received is posted at its stamp and every
  heartbeat moves the clock, and the node checks that its board reaches
  the states the recorded Bulletinboard reached and takes the events it
  took (exit 1 if not); or
- over Zenoh (`--listen tcp/127.0.0.1:7447 --robot fig5`): the node is the
  robot's Bulletinboard on situ's wire protocol (docs/protocol.md). It
  takes the agents' events on `situ/<robot>/event/*`, stamps nothing
  itself (the board's clock is the system's, so events from the future are
  refused), and puts the status on `situ/<robot>/status` at every change
  and every 200 ms. `--until STATE` ends it when the board reaches STATE.

    python3 examples/python/board_node.py examples/mower/mower.situ --recording run.mcap
    python3 examples/python/board_node.py examples/fig5/fig5.situ --listen tcp/127.0.0.1:7447 --until RO

In an rclpy node the same board is fed from the subscriptions' callbacks
(docs/python.md shows the shape).
"""

from __future__ import annotations

import argparse
import json
import queue
import sys
import time
from typing import Any, Optional

import situ

Payload = dict[str, situ.Value]


def payload_of(program: situ.Program, event: str, raw: dict[str, Any]) -> Payload:
    """A message's payload as the board takes it: the wire protocol and the
    recordings write NaN and the infinities as the strings "NaN", "inf",
    "-inf"."""
    types = dict(program.fields(event))
    out: Payload = {}
    for name, value in raw.items():
        if types.get(name) == "f64" and isinstance(value, str):
            out[name] = float(value.replace("NaN", "nan"))
        else:
            out[name] = value
    return out


def show(board: situ.Board, change: situ.Change) -> None:
    print(f"{change.time:10.3f}s  {change.previous} -> {change.state}  ({', '.join(change.rules)})", flush=True)
    for a in board.agents():
        if a.mode != "running":
            continue
        links = "".join(
            [f" from {', '.join(a.reads_from)}" if a.reads_from else "", f" to {', '.join(a.sends_to)}" if a.sends_to else ""]
        )
        print(f"             {a.name} runs {a.function or '-'}(){links}", flush=True)


def from_recording(program: situ.Program, path: str) -> int:
    from mcap.reader import make_reader

    board = situ.Board(program)
    reached: list[str] = []

    def on_change(c: situ.Change) -> None:
        reached.append(c.state)
        show(board, c)

    board.on_change(on_change)
    recorded: list[str] = []
    disagree = 0
    with open(path, "rb") as f:
        for _schema, channel, message in make_reader(f).iter_messages(log_time_order=True):
            m = json.loads(message.data)
            if channel.topic == "/situ/events":
                name = f"{m['agent']}.{m['event']}"
                out = board.post(name, at=m["time_ns"] / 1e9, payload=payload_of(program, m["event"], m["payload"]))
                if out.accepted != m["accepted"]:
                    disagree += 1
                    print(f"the recorded board {'took' if m['accepted'] else 'refused'} {name}; this one: {out}")
            elif channel.topic == "/situ/ticks":
                board.advance(m["time_ns"] / 1e9)
            elif channel.topic == "/state" and m.get("from") != m.get("state"):
                recorded.append(m["state"])
    same = reached == recorded
    c = board.counters()
    print(f"{c.accepted} events taken, not taken: {c.not_taken or 'none'}; {len(reached)} changes", flush=True)
    print("the states agree with the recording" if same else f"the recording went {recorded}, this board {reached}")
    return 0 if same and disagree == 0 else 1


def over_zenoh(program: situ.Program, endpoint: str, robot: str, until: Optional[str], timeout: float) -> int:
    import zenoh

    conf = zenoh.Config()
    conf.insert_json5("mode", '"peer"')
    conf.insert_json5("listen/endpoints", json.dumps([endpoint]))
    conf.insert_json5("scouting/multicast/enabled", "false")
    board = situ.Board(program, clock="system")
    inbox: queue.Queue[dict[str, Any]] = queue.Queue()
    seq = 0

    def on_event(sample: Any) -> None:
        try:
            inbox.put(json.loads(sample.payload.to_string()))
        except ValueError:
            pass  # not JSON: not an event of situ's protocol

    with zenoh.open(conf) as session:
        status = session.declare_publisher(f"situ/{robot}/status")

        def put_status() -> None:
            msg = {"v": 1, "state": board.state, "time_ns": time.time_ns(), "seq": seq}
            status.put(json.dumps(msg))

        def on_change(c: situ.Change) -> None:
            nonlocal seq
            seq += 1
            put_status()
            show(board, c)

        board.on_change(on_change)
        session.declare_subscriber(f"situ/{robot}/event/*", on_event)
        end = time.monotonic() + timeout
        beat = 0.0
        while time.monotonic() < end and board.state != until:
            try:
                m = inbox.get(timeout=0.05)
            except queue.Empty:
                m = None
            if m is not None and m.get("v") == 1:
                try:
                    out = board.post(
                        f"{m['agent']}.{m['event']}",
                        at=m["time_ns"] / 1e9,
                        payload=payload_of(program, m["event"], m.get("payload", {})),
                    )
                    if not out.accepted:
                        print(f"not taken: {out.reason}", flush=True)
                except situ.BoardError as e:
                    print(f"refused: {e}", flush=True)
            if time.monotonic() >= beat:
                board.advance()
                put_status()
                beat = time.monotonic() + 0.2
        if until is not None and board.state != until:
            print(f"no {until} within {timeout} s (in {board.state})", file=sys.stderr)
            return 1
        return 0


def main() -> int:
    ap = argparse.ArgumentParser(description=(__doc__ or "").splitlines()[0])
    ap.add_argument("rules", help="a .situ file or a bundle")
    src = ap.add_mutually_exclusive_group(required=True)
    src.add_argument("--recording", help="an MCAP recording of `situ run`")
    src.add_argument("--listen", help="a Zenoh endpoint to listen on, e.g. tcp/127.0.0.1:7447")
    ap.add_argument("--robot", default="fig5")
    ap.add_argument("--until", help="with --listen: end when the board reaches this state")
    ap.add_argument("--timeout", type=float, default=30.0)
    args = ap.parse_args()
    program = situ.load_path(args.rules)
    if args.recording:
        return from_recording(program, args.recording)
    return over_zenoh(program, args.listen, args.robot, args.until, args.timeout)


if __name__ == "__main__":
    sys.exit(main())
