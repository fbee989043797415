"""The ROS 2 side of the bridge's tests, played by Eclipse Cyclone DDS (the
`cyclonedds` package: one of ROS 2's own middlewares, independent of situ's
RustDDS), with ROS 2's topic and type naming (`rt/…`, `…::msg::dds_::…_`)
and rmw_cyclonedds's service mapping (a request header of the client's
GUID half and sequence number, echoed in the reply).

It plays the AMR of tests/ros2/amr.situ: four lifecycle nodes that answer
`change_state` and `get_state` as rclcpp's lifecycle nodes do, a goal
publisher, a laser driver and the navigator, and a late subscriber of the
bridge's latched `/situ/state`. It prints one JSON line per thing seen:

  {"t": s, "transition": {"node", "label", "from", "to", "ok"}}
  {"t": s, "state": NAME}            on /situ/state
  {"t": s, "error": MESSAGE}         an ERROR status on /diagnostics
  {"t": s, "agents": {AGENT: {"message", "lifecycle"}}}  on /situ/agents
  {"t": s, "step": WHAT}             the scenario's progress
  {"done": true} | {"failed": WHY}

Scenarios: `mission` (goal, obstacle, clear, arrival), `silent-planner`
(the planner answers get_state but never change_state), and `heartbeat`
(the rules of tests/ros2/heartbeat.situ read `/diagnostics`, where the
bridge writes its own status: they must not move until this peer reports
a fault there). With `heartbeat` it also prints
  {"t": s, "step": "own status ignored", "statuses": N}
Run by tests/ros2_bridge.rs; exits 3 when cyclonedds is missing.
"""

import argparse
import json
import os
import sys
import time
import typing
from dataclasses import dataclass, field

sys.path.insert(0, os.path.join(os.path.dirname(__file__), "..", "..", "ros2-map", "tests"))

try:
    import cyclonedds.idl.types as t
    from cyclonedds.core import Policy, Qos
    from cyclonedds.domain import DomainParticipant
    from cyclonedds.idl import IdlStruct
    from cyclonedds.pub import DataWriter
    from cyclonedds.sub import DataReader
    from cyclonedds.topic import Topic
except ImportError as err:
    print(f"cyclonedds is not installed ({err}): python3 -m pip install -r examples/python/requirements.txt", file=sys.stderr)
    sys.exit(3)

from cdr_samples import Bool, DiagnosticArray, DiagnosticStatus, Header, LaserScan, Point, Pose, PoseStamped, Quaternion, State
from cdr_samples import String as StringMsg


@dataclass
class Transition(IdlStruct, typename="lifecycle_msgs::msg::dds_::Transition_"):
    id: t.uint8 = 0
    label: str = ""


# rmw_cyclonedds puts a header before a request's and a reply's fields.
@dataclass
class ChangeStateRequest(IdlStruct, typename="lifecycle_msgs::srv::dds_::ChangeState_Request_"):
    guid: t.uint64 = 0
    seq: t.int64 = 0
    transition: Transition = field(default_factory=Transition)


@dataclass
class ChangeStateReply(IdlStruct, typename="lifecycle_msgs::srv::dds_::ChangeState_Response_"):
    guid: t.uint64 = 0
    seq: t.int64 = 0
    success: bool = False


@dataclass
class GetStateRequest(IdlStruct, typename="lifecycle_msgs::srv::dds_::GetState_Request_"):
    guid: t.uint64 = 0
    seq: t.int64 = 0
    structure_needs_at_least_one_member: t.uint8 = 0


@dataclass
class GetStateReply(IdlStruct, typename="lifecycle_msgs::srv::dds_::GetState_Response_"):
    guid: t.uint64 = 0
    seq: t.int64 = 0
    current_state: State = field(default_factory=State)


LABELS = {1: "unconfigured", 2: "inactive", 3: "active", 4: "finalized"}
# rclcpp's lifecycle: transition id -> (from, to).
MOVES = {1: (1, 2), 2: (2, 1), 3: (2, 3), 4: (3, 2)}

START = time.monotonic()


def say(**what):
    what = {"t": round(time.monotonic() - START, 4), **what}
    print(json.dumps(what), flush=True)


RELIABLE = Qos(Policy.Reliability.Reliable(1_000_000_000), Policy.History.KeepLast(16))
LATCHED = Qos(Policy.Reliability.Reliable(1_000_000_000), Policy.Durability.TransientLocal, Policy.History.KeepLast(1))


class LifecycleNode:
    """A lifecycle node's two services, as rclcpp serves them."""

    def __init__(self, dp, name: str, answers_changes: bool):
        self.name = name
        self.state = 1
        self.answers_changes = answers_changes
        base = name.lstrip("/")
        self.change_rq = DataReader(dp, Topic(dp, f"rq/{base}/change_stateRequest", ChangeStateRequest), qos=RELIABLE)
        self.change_rr = DataWriter(dp, Topic(dp, f"rr/{base}/change_stateReply", ChangeStateReply), qos=RELIABLE)
        self.get_rq = DataReader(dp, Topic(dp, f"rq/{base}/get_stateRequest", GetStateRequest), qos=RELIABLE)
        self.get_rr = DataWriter(dp, Topic(dp, f"rr/{base}/get_stateReply", GetStateReply), qos=RELIABLE)

    def serve(self):
        for rq in self.get_rq.take(16):
            if hasattr(rq, "guid"):
                state = State(id=self.state, label=LABELS[self.state])
                self.get_rr.write(GetStateReply(guid=rq.guid, seq=rq.seq, current_state=state))
        for rq in self.change_rq.take(16):
            if not hasattr(rq, "guid"):
                continue
            before = self.state
            move = MOVES.get(rq.transition.id)
            ok = move is not None and move[0] == self.state
            if not self.answers_changes:
                say(transition={"node": self.name, "label": rq.transition.label, "from": LABELS[before], "to": None, "ok": None})
                continue
            if ok:
                self.state = move[1]
            say(transition={"node": self.name, "label": rq.transition.label, "from": LABELS[before], "to": LABELS[self.state], "ok": ok})
            self.change_rr.write(ChangeStateReply(guid=rq.guid, seq=rq.seq, success=ok))


def scan(nearest: float) -> LaserScan:
    ranges = [3.0] * 360
    ranges[90] = nearest
    return LaserScan(header=Header(frame_id="laser"), angle_min=-3.14, angle_max=3.14, angle_increment=0.0175,
                     scan_time=0.1, range_min=0.05, range_max=10.0, ranges=ranges)


class Peer:
    def __init__(self, domain: int, silent: typing.Optional[str]):
        dp = DomainParticipant(domain)
        self.dp = dp
        names = ["/costmap", "/planner", "/recovery", "/controller"]
        self.nodes = {n: LifecycleNode(dp, n, n != silent) for n in names}
        self.goal = DataWriter(dp, Topic(dp, "rt/goal_pose", PoseStamped), qos=RELIABLE)
        self.scan = DataWriter(dp, Topic(dp, "rt/scan", LaserScan), qos=Qos(Policy.Reliability.BestEffort))
        self.reached = DataWriter(dp, Topic(dp, "rt/goal_reached", Bool), qos=RELIABLE)
        self.diagnostics_topic = Topic(dp, "rt/diagnostics", DiagnosticArray)
        self.diagnostics = DataReader(dp, self.diagnostics_topic, qos=RELIABLE)
        # The bridge's own statuses seen on /diagnostics (`situ: bridge`).
        self.bridge_statuses = 0
        self.agents = DataReader(dp, Topic(dp, "rt/situ/agents", DiagnosticArray), qos=LATCHED)
        self.state_reader = None
        self.state = None

    def follow_state(self):
        """Subscribes to /situ/state now: late, so only a latched topic tells."""
        self.state_reader = DataReader(self.dp, Topic(self.dp, "rt/situ/state", StringMsg), qos=LATCHED)

    def spin(self, seconds: float, until=None) -> bool:
        end = time.monotonic() + seconds
        while time.monotonic() < end:
            for n in self.nodes.values():
                n.serve()
            if self.state_reader is not None:
                for s in self.state_reader.take(16):
                    if hasattr(s, "data") and s.data != self.state:
                        self.state = s.data
                        say(state=s.data)
            for a in self.diagnostics.take(16):
                for status in getattr(a, "status", []):
                    if status.level == 2:
                        say(error=status.message)
                    if status.name == "situ: bridge":
                        self.bridge_statuses += 1
            for a in self.agents.take(16):
                if hasattr(a, "status"):
                    seen = {}
                    for s in a.status:
                        life = [kv.value for kv in s.values if kv.key == "lifecycle"]
                        seen[s.name] = {"message": s.message, "lifecycle": life[0] if life else None}
                    say(agents=seen)
            if until is not None and until():
                return True
            time.sleep(0.002)
        return until is None

    def states(self):
        return {n: node.state for n, node in self.nodes.items()}

    def publish_goal(self):
        pose = Pose(position=Point(x=4.0, y=2.0, z=0.0), orientation=Quaternion(w=1.0))
        self.goal.write(PoseStamped(header=Header(frame_id="map"), pose=pose))


def need(ok: bool, why: str):
    if not ok:
        say(failed=why)
        sys.exit(1)


def scans(peer: Peer, nearest: float, until, seconds: float) -> bool:
    """The laser at 20 Hz until `until` holds."""
    end = time.monotonic() + seconds
    while time.monotonic() < end:
        peer.scan.write(scan(nearest))
        if peer.spin(0.05, until):
            return True
    return False


def mission(peer: Peer):
    configured = lambda: all(s == 2 for s in peer.states().values())
    need(peer.spin(15, configured), f"the nodes were not configured: {peer.states()}")
    say(step="configured")
    peer.follow_state()
    need(peer.spin(5, lambda: peer.state == "IDLE"), "no latched IDLE on /situ/state")
    # The laser reports from the start: its fact must not go stale.
    need(scans(peer, 2.0, None, 0.3) or True, "")
    active = lambda *names: lambda: all(peer.states()[n] == (3 if n in names else 2) for n in peer.nodes)
    # The goal, repeated until heard (a new writer may not be matched yet).
    for _ in range(50):
        peer.publish_goal()
        if scans(peer, 2.0, lambda: peer.state == "NAVIGATING", 0.1):
            break
    need(peer.state == "NAVIGATING", "the goal did not start the mission")
    need(scans(peer, 2.0, active("/costmap", "/planner", "/controller"), 5), f"navigating: {peer.states()}")
    say(step="navigating")
    need(scans(peer, 0.3, lambda: peer.state == "RECOVERING", 5), "the obstacle did not block")
    need(scans(peer, 0.3, active("/costmap", "/recovery", "/controller"), 5), f"recovering: {peer.states()}")
    say(step="recovering")
    need(scans(peer, 1.5, lambda: peer.state == "NAVIGATING", 5), "the clear scan did not resume")
    need(scans(peer, 1.5, active("/costmap", "/planner", "/controller"), 5), f"resumed: {peer.states()}")
    say(step="resumed")
    for _ in range(50):
        peer.reached.write(Bool(data=True))
        if scans(peer, 1.5, lambda: peer.state == "ARRIVED", 0.1):
            break
    need(peer.state == "ARRIVED", "the arrival was not heard")
    need(peer.spin(5, active()), f"arrived: {peer.states()}")
    say(step="arrived")


def silent_planner(peer: Peer):
    """The planner never answers its first `configure`: its failure event
    (PLANNER_DOWN) ends the mission in FAULT; the others stay configured."""
    others = lambda: all(s == 2 for n, s in peer.states().items() if n != "/planner")
    need(peer.spin(15, others), f"the other nodes were not configured: {peer.states()}")
    peer.follow_state()
    need(peer.spin(5, lambda: peer.state == "FAULT"), f"no latched FAULT on /situ/state: {peer.state}")
    # A goal now changes nothing: FAULT is final.
    peer.publish_goal()
    peer.spin(1.0)
    need(peer.state == "FAULT" and others() and peer.states()["/planner"] == 1, f"after: {peer.states()}")
    say(step="fault")


def heartbeat(peer: Peer):
    """The rules post a fault for any status on /diagnostics at all. The
    bridge's own status, once a second there, must not be one: the rules
    stay in RUNNING for three of them; then this peer's own report of a
    fault (level 2) takes them to FAULT."""
    peer.follow_state()
    need(peer.spin(10, lambda: peer.state == "RUNNING"), f"no latched RUNNING on /situ/state: {peer.state}")
    seen = peer.bridge_statuses
    peer.spin(10, lambda: peer.bridge_statuses >= seen + 3 or peer.state != "RUNNING")
    # The bridge's reader gets each status about when this peer does: a
    # little longer for the state it would cause to come back.
    peer.spin(0.5, lambda: peer.state != "RUNNING")
    need(peer.state == "RUNNING", f"the bridge's own status moved the rules to {peer.state}")
    need(peer.bridge_statuses >= seen + 3, f"only {peer.bridge_statuses - seen} statuses of the bridge in 10 s")
    say(step="own status ignored", statuses=peer.bridge_statuses - seen)
    writer = DataWriter(peer.dp, peer.diagnostics_topic, qos=RELIABLE)
    fault = DiagnosticStatus(level=2, name="base: motors", message="motor driver overheated", hardware_id="base")
    # Repeated until heard (a new writer may not be matched yet).
    for _ in range(50):
        writer.write(DiagnosticArray(header=Header(frame_id=""), status=[fault]))
        if peer.spin(0.1, lambda: peer.state == "FAULT"):
            break
    need(peer.state == "FAULT", f"the peer's fault report did not move the rules: {peer.state}")
    say(step="fault")


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("scenario", choices=["mission", "silent-planner", "heartbeat"])
    ap.add_argument("--domain", type=int, default=0)
    args = ap.parse_args()
    peer = Peer(args.domain, "/planner" if args.scenario == "silent-planner" else None)
    say(step="ready")
    scenarios = {"mission": mission, "silent-planner": silent_planner, "heartbeat": heartbeat}
    scenarios[args.scenario](peer)
    print(json.dumps({"done": True}), flush=True)


if __name__ == "__main__":
    main()
