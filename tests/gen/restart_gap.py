"""How long a generated Python agent goes without status after its
Bulletinboard restarts: from the moment the new Bulletinboard accepts
connections to the agent's first status from it (docs/performance.md).

    python3 tests/gen/restart_gap.py SITU AGENT_DIR ROUNDS

SITU is a situ binary built with `--features zenoh`; AGENT_DIR holds
`flight_agent.py`, generated from tests/gen/launch.situ (by any version of
situ: the raw status samples are timed, not the hooks). Run from the
repository's root."""

import os
import signal
import socket
import subprocess
import sys
import tempfile
import threading
import time

AGENT = r"""
import sys, time
import flight_agent as flight

original = flight.Runner._on_status


def timed(self, sample):
    print(f"status {time.time():.6f}", flush=True)
    original(self, sample)


flight.Runner._on_status = timed


class Idle(flight.Handlers):
    def hold(self, step):
        pass


flight.run(Idle(), robot=sys.argv[1], connect=[sys.argv[2]], duration=float(sys.argv[3]))
"""


def free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return int(s.getsockname()[1])


def main() -> None:
    situ, agent_dir, rounds = sys.argv[1], sys.argv[2], int(sys.argv[3])
    port = free_port()
    tmp = tempfile.mkdtemp()
    deploy = os.path.join(tmp, "deploy.toml")
    with open(deploy, "w") as f:
        f.write(
            f'robot = "gap{port}"\n[[process]]\nname = "board"\nboard = true\n'
            f'listen = ["tcp/127.0.0.1:{port}"]\n'
        )
    board_cmd = [situ, "run", "tests/gen/launch.situ", "--transport", "zenoh"]
    board_cmd += ["--deploy", deploy, "--process", "board", "--stack", "none"]
    board_cmd += ["--duration", "600"]

    def board() -> subprocess.Popen[bytes]:
        return subprocess.Popen(board_cmd, stderr=subprocess.DEVNULL)

    def wait_up() -> float:
        while True:
            if b.poll() is not None:
                sys.exit(f"the Bulletinboard ended: {' '.join(board_cmd)}")
            try:
                socket.create_connection(("127.0.0.1", port), 0.05).close()
                return time.time()
            except OSError:
                time.sleep(0.002)

    b = board()
    wait_up()
    script = os.path.join(tmp, "agent.py")
    with open(script, "w") as f:
        f.write(AGENT)
    env = dict(os.environ, PYTHONPATH=os.path.abspath(agent_dir))
    duration = str(10 + rounds * 6)
    agent = subprocess.Popen(
        [sys.executable, script, f"gap{port}", f"tcp/127.0.0.1:{port}", duration],
        stdout=subprocess.PIPE,
        text=True,
        env=env,
    )
    arrivals: list[float] = []

    def read() -> None:
        assert agent.stdout is not None
        for line in agent.stdout:
            if line.startswith("status "):
                arrivals.append(float(line.split()[1]))

    threading.Thread(target=read, daemon=True).start()
    gaps = []
    time.sleep(2.0)
    for _ in range(rounds):
        b.send_signal(signal.SIGKILL)
        b.wait()
        time.sleep(1.0)
        b = board()
        up = wait_up()
        deadline = time.time() + 10.0
        while time.time() < deadline and not any(t > up for t in arrivals):
            time.sleep(0.005)
        after = [t for t in arrivals if t > up]
        gaps.append(after[0] - up if after else float("inf"))
        time.sleep(1.0)
    b.send_signal(signal.SIGKILL)
    agent.kill()
    gaps.sort()
    print("gaps (s):", " ".join(f"{g:.3f}" for g in gaps))
    print(f"median {gaps[len(gaps) // 2]:.3f} s, max {gaps[-1]:.3f} s")


if __name__ == "__main__":
    main()
