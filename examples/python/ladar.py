#!/usr/bin/env python3
"""A LADAR sensor agent in Python, for the example of Fig. 5.

It joins a situ stack over Zenoh with nothing of situ but the wire protocol
(docs/protocol.md): it reports `LAOBN` ("no obstacle") ten times a second,
then, after `--obstacle-after` seconds, `LAOBS` with the obstacle's distance
and height, on `situ/<robot>/event/LADAR`; and it listens to the
Bulletinboard's status on `situ/<robot>/status`, following only the highest
`epoch` it has seen (a lower one is an old leader's, with a standby board).

It exits 0 when the status says RO (the obstacle woke the stack), 1 if
that does not happen within `--timeout` seconds.

    pip install eclipse-zenoh==1.10.2
    python3 examples/python/ladar.py --connect tcp/127.0.0.1:7447 --robot fig5
"""

import argparse
import json
import sys
import threading
import time

import zenoh


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--connect", required=True, help="the Bulletinboard's endpoint, e.g. tcp/127.0.0.1:7447")
    ap.add_argument("--robot", default="fig5")
    ap.add_argument("--obstacle-after", type=float, default=1.0)
    ap.add_argument("--timeout", type=float, default=20.0)
    args = ap.parse_args()

    conf = zenoh.Config()
    conf.insert_json5("mode", '"peer"')
    conf.insert_json5("connect/endpoints", json.dumps([args.connect]))
    conf.insert_json5("scouting/multicast/enabled", "false")

    states = []
    woken = threading.Event()
    epoch = [0]  # the highest epoch seen (absent: 0)

    def on_status(sample):
        msg = json.loads(sample.payload.to_string())
        if msg.get("v") != 1:
            return
        if int(msg.get("epoch", 0)) < epoch[0]:
            return  # an old leader's status: another Bulletinboard leads
        epoch[0] = int(msg.get("epoch", 0))
        if not states or states[-1] != msg["state"]:
            states.append(msg["state"])
            print(f"status: {msg['state']}", flush=True)
        if msg["state"] == "RO":
            woken.set()

    with zenoh.open(conf) as session:
        session.declare_subscriber(f"situ/{args.robot}/status", on_status)
        key = f"situ/{args.robot}/event/LADAR"
        start = time.time()
        while time.time() - start < args.timeout and not woken.is_set():
            now_ns = time.time_ns()
            if time.time() - start >= args.obstacle_after:
                event = {"v": 1, "agent": "LADAR", "event": "LAOBS", "time_ns": now_ns,
                         "payload": {"distance": 12.0, "height": 0.5}}
            else:
                event = {"v": 1, "agent": "LADAR", "event": "LAOBN", "time_ns": now_ns, "payload": {}}
            session.put(key, json.dumps(event))
            time.sleep(0.1)
        if woken.is_set():
            print(f"the Bulletinboard went {' -> '.join(states)}", flush=True)
            return 0
        print(f"no RO within {args.timeout} s; states seen: {states}", file=sys.stderr, flush=True)
        return 1


if __name__ == "__main__":
    sys.exit(main())
