"""The example node (examples/python/board_node.py), run as a user runs it:
on a recording of `situ run`, and as a robot's Bulletinboard over Zenoh
with the Python LADAR of examples/python/ladar.py reporting to it."""

from __future__ import annotations

import json
import socket
import subprocess
import sys
import threading
import time
from pathlib import Path

from conftest import ROOT

NODE = ROOT / "examples" / "python" / "board_node.py"


def test_the_node_on_a_recording_reaches_the_recorded_states(tmp_path: Path, situ_bin: Path) -> None:
    rec = tmp_path / "mower.mcap"
    mower = ROOT / "examples" / "mower" / "mower.situ"
    subprocess.run(
        [str(situ_bin), "run", str(mower), "--script", "a day on the lawn", "--record", str(rec)],
        check=True,
        capture_output=True,
    )
    out = subprocess.run([sys.executable, str(NODE), str(mower), "--recording", str(rec)], capture_output=True, text=True)
    assert out.returncode == 0, out.stdout + out.stderr
    assert "the states agree with the recording" in out.stdout
    assert "MOWING -> FAULT  (blade_stall)" in out.stdout


def free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return int(s.getsockname()[1])


def test_the_node_is_the_bulletinboard_of_a_python_agent_over_zenoh() -> None:
    import zenoh

    port = free_port()
    endpoint = f"tcp/127.0.0.1:{port}"
    fig5 = ROOT / "examples" / "fig5" / "fig5.situ"
    node = subprocess.Popen(
        [sys.executable, str(NODE), str(fig5), "--listen", endpoint, "--robot", "fig5", "--until", "RO", "--timeout", "20"],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
    )
    stop = threading.Event()
    try:
        # The road cameras: the rule `obstacle` needs a straight road too.
        conf = zenoh.Config()
        conf.insert_json5("mode", '"peer"')
        conf.insert_json5("connect/endpoints", json.dumps([endpoint]))
        conf.insert_json5("scouting/multicast/enabled", "false")
        with zenoh.open(conf) as session:

            def cameras() -> None:
                while not stop.is_set():
                    msg = {"v": 1, "agent": "RFCCD", "event": "RFRS", "time_ns": time.time_ns(), "payload": {}}
                    session.put("situ/fig5/event/RFCCD", json.dumps(msg))
                    time.sleep(0.1)

            t = threading.Thread(target=cameras)
            t.start()
            ladar = subprocess.run(
                [sys.executable, str(ROOT / "examples" / "python" / "ladar.py"), "--connect", endpoint,
                 "--robot", "fig5", "--timeout", "15"],
                capture_output=True,
                text=True,
            )
            stop.set()
            t.join()
        out, err = node.communicate(timeout=25)
    finally:
        stop.set()
        if node.poll() is None:
            node.kill()
    assert ladar.returncode == 0, ladar.stdout + ladar.stderr + out + err
    assert "status: RO" in ladar.stdout
    assert node.returncode == 0, out + err
    assert "RS -> RO  (obstacle)" in out
