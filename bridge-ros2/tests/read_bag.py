"""Reads a bag that `situ ros2 --record DIR` wrote, with the `rosbags`
package (PyPI; independent of situ): its metadata, every connection's type,
and every message deserialized by rosbags' own ROS 2 type store from the
bag's `ros2msg` definitions. Prints one JSON object: the message count per
topic, the `/situ/state` sequence, and the nearest range of the last scan.
Run by tests/ros2_bridge.rs; exits 3 when rosbags is missing.
"""

import json
import sys
from pathlib import Path

try:
    from rosbags.highlevel import AnyReader
    from rosbags.typesys import Stores, get_typestore
except ImportError as err:
    print(f"rosbags is not installed ({err}): python3 -m pip install -r examples/python/requirements.txt", file=sys.stderr)
    sys.exit(3)


def main():
    bag = Path(sys.argv[1])
    counts, types, states, nearest = {}, {}, [], None
    with AnyReader([bag], default_typestore=get_typestore(Stores.EMPTY)) as reader:
        for conn in reader.connections:
            types[conn.topic] = conn.msgtype
        for conn, _stamp, raw in reader.messages():
            msg = reader.deserialize(raw, conn.msgtype)
            counts[conn.topic] = counts.get(conn.topic, 0) + 1
            if conn.topic == "/situ/state":
                states.append(msg.data)
            if conn.topic == "/scan":
                nearest = float(min(msg.ranges))
    print(json.dumps({"counts": counts, "types": types, "states": states, "nearest": nearest}))


if __name__ == "__main__":
    main()
