"""The ROS 2 side of the manipulator recipe (docs/ros2.md, "A manipulator"),
played by Eclipse Cyclone DDS: the lifecycle nodes of
tests/ros2/manipulator/manipulator.situ, and the robot's publishers of a
task, the navigate_to_pose action's status (action_msgs/GoalStatusArray),
the joint states (sensor_msgs/JointState), the arm controller's state
(control_msgs/JointTrajectoryControllerState) and the gripper's state, a
message of the robot's own package (picker_msgs/GripperState, from
tests/ros2/manipulator/msgs). It prints peer.py's JSON lines.

Scenarios:
  pick     the task, the base arrives (the last goal of the status list
           succeeds, an older one had already), the arm follows, the
           gripper holds: DONE;
  aborted  the task, then a status list where one goal is aborted: FAULT;
  elbow    the task, then the elbow (found by name among the joints) past
           its limit: FAULT; the shoulder past 2.5 rad before it is not;
  arm      the base arrives, then a joint 0.3 rad off its reference: FAULT.
Run by tests/ros2_bridge.rs; exits 3 when cyclonedds is missing.
"""

import argparse
import os
import sys
import time
from dataclasses import dataclass, field

sys.path.insert(0, os.path.dirname(__file__))

from peer import LATCHED, RELIABLE, LifecycleNode, need, say  # noqa: E402  (exits 3 without cyclonedds)

import cyclonedds.idl.types as t  # noqa: E402
from cyclonedds.domain import DomainParticipant  # noqa: E402
from cyclonedds.idl import IdlStruct  # noqa: E402
from cyclonedds.pub import DataWriter  # noqa: E402
from cyclonedds.sub import DataReader  # noqa: E402
from cyclonedds.topic import Topic  # noqa: E402
from cdr_samples import DiagnosticArray, GoalInfo, GoalStatus, GoalStatusArray, Header, JointState, Quaternion  # noqa: E402
from cdr_samples import Twist, UUID, Vector3  # noqa: E402
from cdr_samples import String as StringMsg  # noqa: E402

f32, f64 = t.float32, t.float64


@dataclass
class GripperState(IdlStruct, typename="picker_msgs::msg::dds_::GripperState_"):
    header: Header = field(default_factory=Header)
    state: t.uint8 = 0
    width: f32 = 0.0
    finger_effort: t.array[f32, 2] = field(default_factory=lambda: [0.0, 0.0])
    faults: t.sequence[str, 4] = field(default_factory=list)


@dataclass
class Duration(IdlStruct, typename="builtin_interfaces::msg::dds_::Duration_"):
    sec: t.int32 = 0
    nanosec: t.uint32 = 0


@dataclass
class JointTrajectoryPoint(IdlStruct, typename="trajectory_msgs::msg::dds_::JointTrajectoryPoint_"):
    positions: t.sequence[f64] = field(default_factory=list)
    velocities: t.sequence[f64] = field(default_factory=list)
    accelerations: t.sequence[f64] = field(default_factory=list)
    effort: t.sequence[f64] = field(default_factory=list)
    time_from_start: Duration = field(default_factory=Duration)


@dataclass
class Transform(IdlStruct, typename="geometry_msgs::msg::dds_::Transform_"):
    translation: Vector3 = field(default_factory=Vector3)
    rotation: Quaternion = field(default_factory=Quaternion)


@dataclass
class MultiDOFJointTrajectoryPoint(IdlStruct, typename="trajectory_msgs::msg::dds_::MultiDOFJointTrajectoryPoint_"):
    transforms: t.sequence[Transform] = field(default_factory=list)
    velocities: t.sequence[Twist] = field(default_factory=list)
    accelerations: t.sequence[Twist] = field(default_factory=list)
    time_from_start: Duration = field(default_factory=Duration)


def point(positions) -> JointTrajectoryPoint:
    return JointTrajectoryPoint(positions=list(positions))


@dataclass
class JointTrajectoryControllerState(IdlStruct,
                                     typename="control_msgs::msg::dds_::JointTrajectoryControllerState_"):
    header: Header = field(default_factory=Header)
    joint_names: t.sequence[str] = field(default_factory=list)
    reference: JointTrajectoryPoint = field(default_factory=JointTrajectoryPoint)
    feedback: JointTrajectoryPoint = field(default_factory=JointTrajectoryPoint)
    error: JointTrajectoryPoint = field(default_factory=JointTrajectoryPoint)
    output: JointTrajectoryPoint = field(default_factory=JointTrajectoryPoint)
    multi_dof_joint_names: t.sequence[str] = field(default_factory=list)
    multi_dof_reference: MultiDOFJointTrajectoryPoint = field(default_factory=MultiDOFJointTrajectoryPoint)
    multi_dof_feedback: MultiDOFJointTrajectoryPoint = field(default_factory=MultiDOFJointTrajectoryPoint)
    multi_dof_error: MultiDOFJointTrajectoryPoint = field(default_factory=MultiDOFJointTrajectoryPoint)
    multi_dof_output: MultiDOFJointTrajectoryPoint = field(default_factory=MultiDOFJointTrajectoryPoint)
    speed_scaling_factor: f64 = 1.0


def controller_state_writer(dp):
    """The arm controller's state with every joint `off` rad from its
    reference, the third joint the other way (so `abs` matters)."""
    writer = DataWriter(dp, Topic(dp, "rt/arm_controller/controller_state", JointTrajectoryControllerState),
                        qos=RELIABLE)
    names = ["shoulder", "elbow", "wrist"]
    reference = [0.4, 1.2, 0.1]

    def write(off: float):
        feedback = [reference[0] + off, reference[1] + off, reference[2] - off]
        errors = [r - f for r, f in zip(reference, feedback)]
        writer.write(JointTrajectoryControllerState(joint_names=names, reference=point(reference),
                                                    feedback=point(feedback), error=point(errors),
                                                    output=point(feedback)))
    return write


EXECUTING, SUCCEEDED, ABORTED = 2, 4, 6
OPEN, CLOSED, HOLDING = 0, 1, 2


def goal(n: int, status: int) -> GoalStatus:
    return GoalStatus(goal_info=GoalInfo(goal_id=UUID(uuid=[n] * 16)), status=status)


class Peer:
    def __init__(self, domain: int):
        dp = DomainParticipant(domain)
        self.dp = dp
        self.nodes = {n: LifecycleNode(dp, n, True) for n in ["/base_controller", "/arm_planner", "/arm_controller"]}
        self.task = DataWriter(dp, Topic(dp, "rt/task", StringMsg), qos=RELIABLE)
        self.nav = DataWriter(dp, Topic(dp, "rt/navigate_to_pose/_action/status", GoalStatusArray), qos=RELIABLE)
        self.joints = DataWriter(dp, Topic(dp, "rt/joint_states", JointState), qos=RELIABLE)
        self.arm = None
        self.gripper = DataWriter(dp, Topic(dp, "rt/gripper/state", GripperState), qos=RELIABLE)
        self.diagnostics = DataReader(dp, Topic(dp, "rt/diagnostics", DiagnosticArray), qos=RELIABLE)
        self.state_reader = DataReader(dp, Topic(dp, "rt/situ/state", StringMsg), qos=LATCHED)
        self.state = None

    def spin(self, seconds: float, until=None) -> bool:
        end = time.monotonic() + seconds
        while time.monotonic() < end:
            for n in self.nodes.values():
                n.serve()
            for s in self.state_reader.take(16):
                if hasattr(s, "data") and s.data != self.state:
                    self.state = s.data
                    say(state=s.data)
            for a in self.diagnostics.take(16):
                for status in getattr(a, "status", []):
                    if status.level == 2:
                        say(error=status.message)
            if until is not None and until():
                return True
            time.sleep(0.002)
        return until is None

    def until_state(self, name: str, publish, seconds: float = 5.0) -> bool:
        """Publishes (a new writer may not be matched yet) until the state is `name`."""
        end = time.monotonic() + seconds
        while time.monotonic() < end:
            publish()
            if self.spin(0.1, lambda: self.state == name):
                return True
        return False

    def joint_states(self, shoulder: float, elbow: float):
        self.joints.write(JointState(name=["shoulder", "elbow", "wrist"], position=[shoulder, elbow, 0.1],
                                     velocity=[0.0] * 3, effort=[0.0] * 3))


def start(peer: Peer):
    configured = lambda: all(n.state == 2 for n in peer.nodes.values())
    need(peer.spin(15, configured), f"the nodes were not configured: {[n.state for n in peer.nodes.values()]}")
    need(peer.spin(5, lambda: peer.state == "IDLE"), "no latched IDLE on /situ/state")
    need(peer.until_state("DRIVING", lambda: peer.task.write(StringMsg(data="pick"))), "the task did not start")
    say(step="driving")


def pick(peer: Peer, arm):
    start(peer)
    # An older goal succeeded, the current one executes: not arrived.
    older = GoalStatusArray(status_list=[goal(1, SUCCEEDED), goal(2, EXECUTING)])
    need(not peer.until_state("PICKING", lambda: peer.nav.write(older), 1.0), "arrived on an older goal")
    done = GoalStatusArray(status_list=[goal(1, SUCCEEDED), goal(2, SUCCEEDED)])
    need(peer.until_state("PICKING", lambda: peer.nav.write(done)), "the last goal's success was not heard")
    say(step="picking")
    # The arm follows its reference within 0.05 rad, the elbow is far from its limit.
    def follow():
        peer.joint_states(0.4, 1.2)
        arm(0.05)
    need(not peer.until_state("FAULT", follow, 1.0), "a fault on a good trajectory")
    grip = lambda: peer.gripper.write(GripperState(state=HOLDING, width=0.042, finger_effort=[8.0, 8.0]))
    need(peer.until_state("DONE", grip), "the grasp was not heard")
    say(step="done")


def arm_off(peer: Peer, arm):
    start(peer)
    done = GoalStatusArray(status_list=[goal(1, SUCCEEDED)])
    need(peer.until_state("PICKING", lambda: peer.nav.write(done)), "the goal's success was not heard")
    need(peer.until_state("FAULT", lambda: arm(0.3)), "the arm 0.3 rad off its reference was not heard")
    say(step="fault")


def aborted(peer: Peer, _arm):
    start(peer)
    listed = GoalStatusArray(status_list=[goal(1, SUCCEEDED), goal(2, ABORTED), goal(3, EXECUTING)])
    need(peer.until_state("FAULT", lambda: peer.nav.write(listed)), "an aborted goal was not heard")
    say(step="fault")


def elbow(peer: Peer, _arm):
    start(peer)
    need(not peer.until_state("FAULT", lambda: peer.joint_states(2.8, 1.0), 1.0), "the shoulder taken for the elbow")
    need(peer.until_state("FAULT", lambda: peer.joint_states(0.2, -2.8)), "the elbow past its limit was not heard")
    say(step="fault")


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("scenario", choices=["pick", "aborted", "elbow", "arm"])
    ap.add_argument("--domain", type=int, default=0)
    args = ap.parse_args()
    peer = Peer(args.domain)
    arm = controller_state_writer(peer.dp)
    say(step="ready")
    {"pick": pick, "aborted": aborted, "elbow": elbow, "arm": arm_off}[args.scenario](peer, arm)
    print('{"done": true}', flush=True)


if __name__ == "__main__":
    main()
