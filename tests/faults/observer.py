#!/usr/bin/env python3
"""An agent host's view of the Bulletinboard, for the fault tests.

    python3 observer.py --connect tcp/10.20.0.1:7447 --robot fig5 [--mode peer|client]

It subscribes to `situ/<robot>/status` through one Zenoh link (gossip and
multicast scouting off) and prints one JSON line per status message, as it
arrives: `at_ns` (its arrival, `time.time_ns()`), `state`, `seq`,
`time_ns` (the board's stamp) and, when the message has them, `epoch` and
`board`. A first line `{"ready": true}` says the subscriber is declared.
It runs until killed, or `--duration` seconds.
"""

import argparse
import json
import sys
import time

import zenoh


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--connect", required=True, help="a Zenoh endpoint, e.g. tcp/10.20.0.1:7447")
    ap.add_argument("--robot", default="fig5")
    ap.add_argument("--mode", default="peer", choices=["peer", "client"])
    ap.add_argument("--duration", type=float, default=3600.0)
    args = ap.parse_args()

    conf = zenoh.Config()
    conf.insert_json5("mode", json.dumps(args.mode))
    conf.insert_json5("connect/endpoints", json.dumps([args.connect]))
    conf.insert_json5("scouting/multicast/enabled", "false")
    conf.insert_json5("scouting/gossip/enabled", "false")
    # Wait for the other end (it may start after us) and come back to it.
    conf.insert_json5("connect/timeout_ms", "-1")
    conf.insert_json5("connect/exit_on_failure", "false")
    conf.insert_json5("connect/retry", '{"period_init_ms": 100, "period_max_ms": 500, "period_increase_factor": 2}')

    def on_status(sample: zenoh.Sample) -> None:
        at = time.time_ns()
        try:
            msg = json.loads(sample.payload.to_string())
        except ValueError:
            return
        line = {"at_ns": at, "state": msg.get("state"), "seq": msg.get("seq"), "time_ns": msg.get("time_ns")}
        for key in ("epoch", "board"):
            if key in msg:
                line[key] = msg[key]
        print(json.dumps(line), flush=True)

    with zenoh.open(conf) as session:
        session.declare_subscriber(f"situ/{args.robot}/status", on_status)
        print(json.dumps({"ready": True}), flush=True)
        time.sleep(args.duration)
    return 0


if __name__ == "__main__":
    sys.exit(main())
