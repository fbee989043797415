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

sys.path.insert(0, os.path.dirname(__file__))

from peer import LATCHED, RELIABLE  # noqa: E402  (exits 3 without cyclonedds; puts cdr_samples on the path)

import cyclonedds.idl.types as t  # noqa: E402
from cyclonedds.domain import DomainParticipant  # noqa: E402
from cyclonedds.idl import IdlStruct  # noqa: E402
from cyclonedds.pub import DataWriter  # noqa: E402
from cyclonedds.sub import DataReader  # noqa: E402
from cyclonedds.topic import Topic  # noqa: E402

from cdr_samples import UUID, GoalInfo, GoalStatus, GoalStatusArray, Header, JointState, Time  # noqa: E402
from cdr_samples import String as StringMsg  # noqa: E402


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
    joints = DataWriter(dp, Topic(dp, "rt/joint_states", JointState), qos=RELIABLE)
    feedback = DataWriter(dp, Topic(dp, "rt/gripper/_action/feedback", GripperFeedbackMessage), qos=RELIABLE)
    status = DataWriter(dp, Topic(dp, "rt/navigate/_action/status", GoalStatusArray), qos=RELIABLE)
    state_reader = DataReader(dp, Topic(dp, "rt/situ/state", StringMsg), qos=LATCHED)
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
