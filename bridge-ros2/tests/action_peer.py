"""A ROS 2 robot's joints and actions, played by Eclipse Cyclone DDS (the
`cyclonedds` package) for tests/ros2_bridge.rs: at 20 Hz it publishes a
`sensor_msgs/JointState` on /joint_states, the feedback of a
`control_msgs/action/GripperCommand` on /gripper/_action/feedback (DDS type
`control_msgs::action::dds_::GripperCommand_FeedbackMessage_`) and an
`action_msgs/GoalStatusArray` on /navigate/_action/status, and follows the
bridge's latched /situ/state until it is ABORTED (exit 0) or 20 s pass
(exit 1). Prints each state seen as a JSON line.
"""

import json
import os
import sys
import time
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

from cdr_samples import UUID, GoalInfo, GoalStatus, GoalStatusArray, Header, JointState, Time
from cdr_samples import String as StringMsg


@dataclass
class GripperFeedback(IdlStruct, typename="control_msgs::action::dds_::GripperCommand_Feedback_"):
    position: t.float64 = 0.0
    effort: t.float64 = 0.0
    stalled: bool = False
    reached_goal: bool = False


@dataclass
class GripperFeedbackMessage(IdlStruct, typename="control_msgs::action::dds_::GripperCommand_FeedbackMessage_"):
    goal_id: UUID = field(default_factory=UUID)
    feedback: GripperFeedback = field(default_factory=GripperFeedback)


def main():
    domain = int(sys.argv[1])
    dp = DomainParticipant(domain)
    reliable = Qos(Policy.Reliability.Reliable(1_000_000_000), Policy.History.KeepLast(16))
    latched = Qos(Policy.Reliability.Reliable(1_000_000_000), Policy.Durability.TransientLocal, Policy.History.KeepLast(1))
    joints = DataWriter(dp, Topic(dp, "rt/joint_states", JointState), qos=reliable)
    feedback = DataWriter(dp, Topic(dp, "rt/gripper/_action/feedback", GripperFeedbackMessage), qos=reliable)
    status = DataWriter(dp, Topic(dp, "rt/navigate/_action/status", GoalStatusArray), qos=reliable)
    state_reader = DataReader(dp, Topic(dp, "rt/situ/state", StringMsg), qos=latched)
    goal = UUID(list(range(16)))
    state, end = None, time.monotonic() + 20
    while time.monotonic() < end:
        joints.write(JointState(Header(), ["a", "b", "c"], [0.1, -0.2, 0.3], [], []))
        if state == "GRIPPING":
            feedback.write(GripperFeedbackMessage(goal, GripperFeedback(0.021, 40.0, True, False)))
        if state == "STALLED":
            status.write(GoalStatusArray([GoalStatus(GoalInfo(goal, Time(1, 0)), 6)]))
        for s in state_reader.take(16):
            if hasattr(s, "data") and s.data != state:
                state = s.data
                print(json.dumps({"state": state}), flush=True)
        if state == "ABORTED":
            return
        time.sleep(0.05)
    print(json.dumps({"failed": f"still {state}"}), flush=True)
    sys.exit(1)


if __name__ == "__main__":
    main()
