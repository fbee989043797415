#!/usr/bin/env python3
"""Reads a recording made by `situ run --record F.mcap` with the `mcap`
package from PyPI (the reader Foxglove's tooling uses), counts the messages
per topic and checks the schemas Foxglove's panels need:

- `foxglove.Log` on /events and /diagnostics,
- `foxglove.PoseInFrame` on /pose, `foxglove.SceneUpdate` on /obstacles,
- a /state channel whose messages have a `state` field (Foxglove's State
  Transitions panel draws it), and the attached bundle;
- every message valid against its channel's JSON schema (the `jsonschema`
  package), and the Foxglove schemas in full: every object in them lists
  its properties and the required ones (a stub `{"type": "object"}` fails,
  and so does a field of the wrong name, a required one being missing).

Usage: read_mcap.py RECORDING.mcap [--stand-ins]   (exit 0 when everything holds)

With --stand-ins (a scripted run of any rules file: no vehicle), /pose and
/obstacles are not expected; every agent's modes on /situ/modes are.
"""
import json
import sys

import jsonschema
from mcap.reader import make_reader


def stubs(node, where="#"):
    """The places in a Foxglove schema where an object does not say its
    properties and the required ones."""
    found = []
    if isinstance(node, dict):
        if node.get("type") == "object" and (not node.get("properties") or "required" not in node):
            found.append(where)
        for k, v in node.items():
            found += stubs(v, f"{where}/{k}")
    elif isinstance(node, list):
        for i, v in enumerate(node):
            found += stubs(v, f"{where}/{i}")
    return found


def main(path, stand_ins=False):
    counts = {}
    schemas = {}
    states = []
    first_pose = None
    first_scene = None
    validators = {}
    invalid = {}
    stubbed = {}
    with open(path, "rb") as f:
        reader = make_reader(f)
        for schema, channel, message in reader.iter_messages():
            counts[channel.topic] = counts.get(channel.topic, 0) + 1
            schemas[channel.topic] = (schema.name, schema.encoding, channel.message_encoding)
            if schema.id not in validators:
                doc = json.loads(schema.data)
                cls = jsonschema.validators.validator_for(doc)
                cls.check_schema(doc)
                validators[schema.id] = cls(doc)
                if schema.name.startswith("foxglove."):
                    # The timestamps' `time` and `duration` objects list
                    # no required fields in Foxglove's own schemas.
                    found = [w for w in stubs(doc) if not w.endswith(("/timestamp", "/lifetime"))]
                    if found:
                        stubbed[channel.topic] = found
            errors = list(validators[schema.id].iter_errors(json.loads(message.data)))
            if errors and channel.topic not in invalid:
                e = errors[0]
                invalid[channel.topic] = f"{e.message} at {'/'.join(map(str, e.absolute_path)) or 'the top'}"
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
    for topic, why in sorted(invalid.items()):
        check(False, f"{topic}: a message does not validate against its schema: {why}")
    for topic, where in sorted(stubbed.items()):
        check(False, f"{topic}: the schema {schemas[topic][0]} is a stub at {', '.join(where[:5])}")
    print("states:", " -> ".join(states))
    if failures:
        for f in failures:
            print("FAIL:", f, file=sys.stderr)
        return 1
    print(f"ok: readable by the mcap package, Foxglove schemas in place, {sum(counts.values())} messages valid")
    return 0


if __name__ == "__main__":
    args = sys.argv[1:]
    if len(args) not in (1, 2) or (len(args) == 2 and args[1] != "--stand-ins"):
        print(__doc__, file=sys.stderr)
        sys.exit(2)
    sys.exit(main(args[0], stand_ins=len(args) == 2))
