#!/usr/bin/env python3
"""Reads a recording made by `situ run --record F.mcap` with the `mcap`
package from PyPI (the reader Foxglove's tooling uses), counts the messages
per topic and checks the schemas Foxglove's panels need:

- `foxglove.Log` on /events and /diagnostics,
- `foxglove.PoseInFrame` on /pose, `foxglove.SceneUpdate` on /obstacles,
- a /state channel whose messages have a `state` field (Foxglove's State
  Transitions panel draws it), and the attached bundle.

Usage: read_mcap.py RECORDING.mcap [--stand-ins]   (exit 0 when everything holds)

With --stand-ins (a scripted run of any rules file: no vehicle), /pose and
/obstacles are not expected; every agent's modes on /situ/modes are.
"""
import json
import sys

from mcap.reader import make_reader


def main(path, stand_ins=False):
    counts = {}
    schemas = {}
    states = []
    first_pose = None
    first_scene = None
    with open(path, "rb") as f:
        reader = make_reader(f)
        for schema, channel, message in reader.iter_messages():
            counts[channel.topic] = counts.get(channel.topic, 0) + 1
            schemas[channel.topic] = (schema.name, schema.encoding, channel.message_encoding)
            if channel.topic in ("/state", "/pose", "/obstacles"):
                body = json.loads(message.data)
                if channel.topic == "/state":
                    states.append(body["state"])
                elif channel.topic == "/pose" and first_pose is None:
                    first_pose = body
                elif channel.topic == "/obstacles" and first_scene is None:
                    first_scene = body
        f.seek(0)
        attachments = [a.name for a in make_reader(f).iter_attachments()]

    failures = []

    def check(cond, what):
        if not cond:
            failures.append(what)

    for topic, n in sorted(counts.items()):
        name, enc, msg_enc = schemas[topic]
        print(f"{topic:<16} {n:>8}  {name} ({enc}, {msg_enc})")
    if stand_ins:
        want = {"/events": "foxglove.Log", "/state": None, "/situ/modes": None}
    else:
        want = {
            "/events": "foxglove.Log",
            "/pose": "foxglove.PoseInFrame",
            "/obstacles": "foxglove.SceneUpdate",
            "/state": None,
        }
    for topic, name in want.items():
        check(counts.get(topic, 0) > 0, f"no message on {topic}")
        if name and topic in schemas:
            check(schemas[topic][0] == name, f"{topic} has schema {schemas[topic][0]}, not {name}")
    if "/diagnostics" in schemas:
        check(schemas["/diagnostics"][0] == "foxglove.Log", "/diagnostics is not foxglove.Log")
    for topic, (_, enc, msg_enc) in schemas.items():
        check(enc == "jsonschema" and msg_enc == "json", f"{topic} is not JSON with a jsonschema schema")
    check(len(states) > 0 and all(isinstance(s, str) and s for s in states), "/state messages lack `state`")
    if first_pose is not None:
        check("position" in first_pose.get("pose", {}) and first_pose.get("frame_id"), "/pose is not a PoseInFrame")
    if first_scene is not None:
        check(isinstance(first_scene.get("entities"), list) and first_scene["entities"], "/obstacles has no entities")
    check("bundle.json" in attachments, "the bundle is not attached")
    print("states:", " -> ".join(states))
    if failures:
        for f in failures:
            print("FAIL:", f, file=sys.stderr)
        return 1
    print("ok: readable by the mcap package, Foxglove schemas in place")
    return 0


if __name__ == "__main__":
    args = sys.argv[1:]
    if len(args) not in (1, 2) or (len(args) == 2 and args[1] != "--stand-ins"):
        print(__doc__, file=sys.stderr)
        sys.exit(2)
    sys.exit(main(args[0], stand_ins=len(args) == 2))
