#!/usr/bin/env python3
"""A Foxglove WebSocket client (protocol foxglove.sdk.v1, or its former name
foxglove.websocket.v1, spoken with
the `websockets` package from PyPI) watching a `situ run --foxglove` run:
it connects (retrying while the server starts), takes the advertised
channels, subscribes to all of them and receives the binary message frames
until the server closes. Then it checks what it received:

- the channels Foxglove's panels need, with their schema names, JSON
  messages and jsonschema schemas;
- messages on /pose, /obstacles, /state and /events (with --rules-only, a
  run of rules without a simulated vehicle: /state and /events), each one
  valid against its channel's advertised schema (the `jsonschema` package);
- with --recording F.mcap (the same run's --record): the same channels and
  schemas as the recording, and every message received live is the
  recording's message of that topic and time, byte for byte.

Usage: foxglove_client.py ws://HOST:PORT [--recording F.mcap] [--rules-only]
Exit 0 when everything holds.
"""
import json
import struct
import sys
import time

import jsonschema
import websockets
from websockets.sync.client import connect

WANT = {
    "/pose": "foxglove.PoseInFrame",
    "/obstacles": "foxglove.SceneUpdate",
    "/state": "situ.State",
    "/events": "foxglove.Log",
}


def watch(url):
    """The advertised channels (id -> channel) and the messages received
    (topic -> [(log time, bytes)])."""
    deadline = time.time() + 60
    while True:
        try:
            ws = connect(url, subprotocols=["foxglove.sdk.v1", "foxglove.websocket.v1"], open_timeout=5, max_size=None)
            break
        except (OSError, websockets.exceptions.InvalidHandshake) as e:
            if time.time() > deadline:
                raise SystemExit(f"FAIL: no Foxglove server at {url}: {e}")
            time.sleep(0.2)
    channels = {}
    subs = {}
    received = {}
    with ws:
        last_advert = time.time()
        subscribed = False
        while True:
            try:
                frame = ws.recv(timeout=0.3 if not subscribed else 120)
            except TimeoutError:
                if not subscribed and channels and time.time() - last_advert > 0.2:
                    # Every channel advertised: subscribe to them all at once.
                    request = []
                    for i, cid in enumerate(sorted(channels)):
                        subs[i + 1] = cid
                        request.append({"id": i + 1, "channelId": cid})
                    ws.send(json.dumps({"op": "subscribe", "subscriptions": request}))
                    subscribed = True
                    continue
                if subscribed:
                    raise SystemExit("FAIL: no message for 120 s")
                continue
            except websockets.exceptions.ConnectionClosed:
                break
            if isinstance(frame, str):
                msg = json.loads(frame)
                if msg.get("op") == "advertise":
                    for ch in msg["channels"]:
                        channels[ch["id"]] = ch
                    last_advert = time.time()
            elif frame and frame[0] == 0x01:
                sub, log_time = struct.unpack_from("<IQ", frame, 1)
                topic = channels[subs[sub]]["topic"]
                received.setdefault(topic, []).append((log_time, bytes(frame[13:])))
    return channels, received


def recorded(path):
    """The recording's channels (topic -> (schema name, schema)) and
    messages (topic -> {(log time, bytes)})."""
    from mcap.reader import make_reader

    chans = {}
    msgs = {}
    with open(path, "rb") as f:
        reader = make_reader(f)
        summary = reader.get_summary()
        for ch in summary.channels.values():
            s = summary.schemas[ch.schema_id]
            chans[ch.topic] = (s.name, s.data.decode())
        for _, ch, m in reader.iter_messages():
            msgs.setdefault(ch.topic, set()).add((m.log_time, bytes(m.data)))
    return chans, msgs


def main(url, recording=None, rules_only=False):
    channels, received = watch(url)
    failures = []

    def check(cond, what):
        if not cond:
            failures.append(what)

    by_topic = {ch["topic"]: ch for ch in channels.values()}
    validators = {}
    for topic, ch in sorted(by_topic.items()):
        check(ch["encoding"] == "json", f"{topic}: messages are {ch['encoding']}, not json")
        check(ch.get("schemaEncoding") == "jsonschema", f"{topic}: schema is {ch.get('schemaEncoding')}, not jsonschema")
        doc = json.loads(ch["schema"])
        cls = jsonschema.validators.validator_for(doc)
        cls.check_schema(doc)
        validators[topic] = cls(doc)
        print(f"{topic:<16} {len(received.get(topic, [])):>8}  {ch['schemaName']}")
    want = {t: n for t, n in WANT.items() if not (rules_only and t in ("/pose", "/obstacles"))}
    for topic, name in want.items():
        check(topic in by_topic, f"{topic} is not advertised")
        if topic in by_topic:
            check(by_topic[topic]["schemaName"] == name, f"{topic} has schema {by_topic[topic]['schemaName']}, not {name}")
        check(received.get(topic), f"no message received on {topic}")
    for topic, msgs in received.items():
        for _, data in msgs:
            errors = list(validators[topic].iter_errors(json.loads(data)))
            if errors:
                check(False, f"{topic}: a message does not validate against its schema: {errors[0].message}")
                break
    if recording:
        chans, msgs = None, None
        for _ in range(50):  # the run writes the recording's end as it stops
            try:
                chans, msgs = recorded(recording)
                break
            except Exception:  # noqa: BLE001 - not finished yet
                time.sleep(0.2)
        check(chans is not None, f"the recording {recording} does not read")
        if chans is not None:
            live = {t: (ch["schemaName"], ch["schema"]) for t, ch in by_topic.items()}
            check(live == chans, f"the live channels and schemas differ from the recording's: {sorted(live)} vs {sorted(chans)}")
            for topic, got in received.items():
                extra = [m for m in got if m not in msgs.get(topic, set())]
                check(not extra, f"{topic}: {len(extra)} live messages are not the recording's")
            total = sum(len(v) for v in msgs.values())
            live_total = sum(len(v) for v in received.values())
            print(f"recording: {total} messages; live: {live_total}")
    if failures:
        for f in failures:
            print("FAIL:", f, file=sys.stderr)
        return 1
    print(f"ok: {len(by_topic)} channels, {sum(len(v) for v in received.values())} messages received live")
    return 0


if __name__ == "__main__":
    args = sys.argv[1:]
    rules_only = "--rules-only" in args
    args = [a for a in args if a != "--rules-only"]
    if len(args) == 1:
        sys.exit(main(args[0], rules_only=rules_only))
    if len(args) == 3 and args[1] == "--recording":
        sys.exit(main(args[0], args[2], rules_only))
    print(__doc__, file=sys.stderr)
    sys.exit(2)
