"""ROS 2 messages serialized to CDR by Eclipse Cyclone DDS (the `cyclonedds`
package), an implementation independent of situ's decoder.

Prints one JSON line per message:
{"name": ..., "type": "pkg/msg/Name", "cdr_hex": ..., "expect": {path: value}, "f32": [paths]}
where `expect` holds every leaf of the message by its field path as the map
writes it (`status[0].values[1].key`), NaN and infinities as the strings
"nan", "inf", "-inf", and `f32` lists the paths of float32 leaves.
Run by ros2-map/tests/cdr_cyclonedds.rs; exits 3 when cyclonedds is missing.
"""

import dataclasses
import json
import math
import sys
import typing
from dataclasses import dataclass, field

try:
    from cyclonedds.idl import Endianness, IdlStruct
    import cyclonedds.idl.types as t
except ImportError as err:
    print(f"cyclonedds is not installed ({err}): python3 -m pip install -r examples/python/requirements.txt", file=sys.stderr)
    sys.exit(3)

f32, f64 = t.float32, t.float64


@dataclass
class Time(IdlStruct, typename="builtin_interfaces::msg::dds_::Time_"):
    sec: t.int32 = 0
    nanosec: t.uint32 = 0


@dataclass
class Header(IdlStruct, typename="std_msgs::msg::dds_::Header_"):
    stamp: Time = field(default_factory=Time)
    frame_id: str = ""


@dataclass
class Bool(IdlStruct, typename="std_msgs::msg::dds_::Bool_"):
    data: bool = False


@dataclass
class Int32(IdlStruct, typename="std_msgs::msg::dds_::Int32_"):
    data: t.int32 = 0


@dataclass
class Int64(IdlStruct, typename="std_msgs::msg::dds_::Int64_"):
    data: t.int64 = 0


@dataclass
class Float32(IdlStruct, typename="std_msgs::msg::dds_::Float32_"):
    data: f32 = 0.0


@dataclass
class Float64(IdlStruct, typename="std_msgs::msg::dds_::Float64_"):
    data: f64 = 0.0


@dataclass
class String(IdlStruct, typename="std_msgs::msg::dds_::String_"):
    data: str = ""


@dataclass
class Empty(IdlStruct, typename="std_msgs::msg::dds_::Empty_"):
    structure_needs_at_least_one_member: t.uint8 = 0


@dataclass
class Point(IdlStruct, typename="geometry_msgs::msg::dds_::Point_"):
    x: f64 = 0.0
    y: f64 = 0.0
    z: f64 = 0.0


@dataclass
class Vector3(IdlStruct, typename="geometry_msgs::msg::dds_::Vector3_"):
    x: f64 = 0.0
    y: f64 = 0.0
    z: f64 = 0.0


@dataclass
class Quaternion(IdlStruct, typename="geometry_msgs::msg::dds_::Quaternion_"):
    x: f64 = 0.0
    y: f64 = 0.0
    z: f64 = 0.0
    w: f64 = 1.0


@dataclass
class Pose(IdlStruct, typename="geometry_msgs::msg::dds_::Pose_"):
    position: Point = field(default_factory=Point)
    orientation: Quaternion = field(default_factory=Quaternion)


@dataclass
class PoseWithCovariance(IdlStruct, typename="geometry_msgs::msg::dds_::PoseWithCovariance_"):
    pose: Pose = field(default_factory=Pose)
    covariance: t.array[f64, 36] = field(default_factory=lambda: [0.0] * 36)


@dataclass
class Twist(IdlStruct, typename="geometry_msgs::msg::dds_::Twist_"):
    linear: Vector3 = field(default_factory=Vector3)
    angular: Vector3 = field(default_factory=Vector3)


@dataclass
class TwistWithCovariance(IdlStruct, typename="geometry_msgs::msg::dds_::TwistWithCovariance_"):
    twist: Twist = field(default_factory=Twist)
    covariance: t.array[f64, 36] = field(default_factory=lambda: [0.0] * 36)


@dataclass
class PoseStamped(IdlStruct, typename="geometry_msgs::msg::dds_::PoseStamped_"):
    header: Header = field(default_factory=Header)
    pose: Pose = field(default_factory=Pose)


@dataclass
class Odometry(IdlStruct, typename="nav_msgs::msg::dds_::Odometry_"):
    header: Header = field(default_factory=Header)
    child_frame_id: str = ""
    pose: PoseWithCovariance = field(default_factory=PoseWithCovariance)
    twist: TwistWithCovariance = field(default_factory=TwistWithCovariance)


@dataclass
class LaserScan(IdlStruct, typename="sensor_msgs::msg::dds_::LaserScan_"):
    header: Header = field(default_factory=Header)
    angle_min: f32 = 0.0
    angle_max: f32 = 0.0
    angle_increment: f32 = 0.0
    time_increment: f32 = 0.0
    scan_time: f32 = 0.0
    range_min: f32 = 0.0
    range_max: f32 = 0.0
    ranges: t.sequence[f32] = field(default_factory=list)
    intensities: t.sequence[f32] = field(default_factory=list)


@dataclass
class BatteryState(IdlStruct, typename="sensor_msgs::msg::dds_::BatteryState_"):
    header: Header = field(default_factory=Header)
    voltage: f32 = 0.0
    temperature: f32 = 0.0
    current: f32 = 0.0
    charge: f32 = 0.0
    capacity: f32 = 0.0
    design_capacity: f32 = 0.0
    percentage: f32 = 0.0
    power_supply_status: t.uint8 = 0
    power_supply_health: t.uint8 = 0
    power_supply_technology: t.uint8 = 0
    present: bool = False
    cell_voltage: t.sequence[f32] = field(default_factory=list)
    cell_temperature: t.sequence[f32] = field(default_factory=list)
    location: str = ""
    serial_number: str = ""


@dataclass
class Imu(IdlStruct, typename="sensor_msgs::msg::dds_::Imu_"):
    header: Header = field(default_factory=Header)
    orientation: Quaternion = field(default_factory=Quaternion)
    orientation_covariance: t.array[f64, 9] = field(default_factory=lambda: [0.0] * 9)
    angular_velocity: Vector3 = field(default_factory=Vector3)
    angular_velocity_covariance: t.array[f64, 9] = field(default_factory=lambda: [0.0] * 9)
    linear_acceleration: Vector3 = field(default_factory=Vector3)
    linear_acceleration_covariance: t.array[f64, 9] = field(default_factory=lambda: [0.0] * 9)


@dataclass
class NavSatStatus(IdlStruct, typename="sensor_msgs::msg::dds_::NavSatStatus_"):
    status: t.int8 = 0
    service: t.uint16 = 0


@dataclass
class NavSatFix(IdlStruct, typename="sensor_msgs::msg::dds_::NavSatFix_"):
    header: Header = field(default_factory=Header)
    status: NavSatStatus = field(default_factory=NavSatStatus)
    latitude: f64 = 0.0
    longitude: f64 = 0.0
    altitude: f64 = 0.0
    position_covariance: t.array[f64, 9] = field(default_factory=lambda: [0.0] * 9)
    position_covariance_type: t.uint8 = 0


@dataclass
class Range(IdlStruct, typename="sensor_msgs::msg::dds_::Range_"):
    header: Header = field(default_factory=Header)
    radiation_type: t.uint8 = 0
    field_of_view: f32 = 0.0
    min_range: f32 = 0.0
    max_range: f32 = 0.0
    range: f32 = 0.0
    variance: f32 = 0.0  # since ROS 2 Jazzy


@dataclass
class KeyValue(IdlStruct, typename="diagnostic_msgs::msg::dds_::KeyValue_"):
    key: str = ""
    value: str = ""


@dataclass
class DiagnosticStatus(IdlStruct, typename="diagnostic_msgs::msg::dds_::DiagnosticStatus_"):
    level: t.uint8 = 0  # `byte` in the .msg: an octet on the wire
    name: str = ""
    message: str = ""
    hardware_id: str = ""
    values: t.sequence[KeyValue] = field(default_factory=list)


@dataclass
class DiagnosticArray(IdlStruct, typename="diagnostic_msgs::msg::dds_::DiagnosticArray_"):
    header: Header = field(default_factory=Header)
    status: t.sequence[DiagnosticStatus] = field(default_factory=list)


@dataclass
class State(IdlStruct, typename="lifecycle_msgs::msg::dds_::State_"):
    id: t.uint8 = 0
    label: str = ""


@dataclass
class JointState(IdlStruct, typename="sensor_msgs::msg::dds_::JointState_"):
    header: Header = field(default_factory=Header)
    name: t.sequence[str] = field(default_factory=list)
    position: t.sequence[f64] = field(default_factory=list)
    velocity: t.sequence[f64] = field(default_factory=list)
    effort: t.sequence[f64] = field(default_factory=list)


@dataclass
class UUID(IdlStruct, typename="unique_identifier_msgs::msg::dds_::UUID_"):
    uuid: t.array[t.uint8, 16] = field(default_factory=lambda: [0] * 16)


@dataclass
class GoalInfo(IdlStruct, typename="action_msgs::msg::dds_::GoalInfo_"):
    goal_id: UUID = field(default_factory=UUID)
    stamp: Time = field(default_factory=Time)


@dataclass
class GoalStatus(IdlStruct, typename="action_msgs::msg::dds_::GoalStatus_"):
    goal_info: GoalInfo = field(default_factory=GoalInfo)
    status: t.int8 = 0


@dataclass
class GoalStatusArray(IdlStruct, typename="action_msgs::msg::dds_::GoalStatusArray_"):
    status_list: t.sequence[GoalStatus] = field(default_factory=list)


# A package of the tests' own: tests/ros2/msgs/arm_msgs.
@dataclass
class Gripper(IdlStruct, typename="arm_msgs::msg::dds_::Gripper_"):
    gap: f32 = 0.0
    closed: bool = False
    forces: t.sequence[t.int16, 4] = field(default_factory=list)


@dataclass
class ArmStatus(IdlStruct, typename="arm_msgs::msg::dds_::ArmStatus_"):
    header: Header = field(default_factory=Header)
    mode: t.uint8 = 0
    joints: t.array[f64, 6] = field(default_factory=lambda: [0.0] * 6)
    gripper: Gripper = field(default_factory=Gripper)
    tool: t.bounded_str[32] = ""


def full_name(msg) -> str:
    # `pkg::msg::dds_::Name_`, the ROS 2 naming of DDS types.
    pkg, kind, _, name = type(msg).__idl_typename__.split("::")
    return f"{pkg}/{kind}/{name.rstrip('_')}"


def leaves(value, hint, path, out, f32s):
    """Every leaf of `value` (declared as `hint`) by its field path."""
    if dataclasses.is_dataclass(value):
        hints = typing.get_type_hints(type(value), include_extras=True)
        for f in dataclasses.fields(value):
            if f.name == "structure_needs_at_least_one_member":
                continue
            sub = f"{path}.{f.name}" if path else f.name
            leaves(getattr(value, f.name), hints[f.name], sub, out, f32s)
    elif isinstance(value, (list, tuple)):
        for i, item in enumerate(value):
            leaves(item, hint, f"{path}[{i}]", out, f32s)
        out[f"len({path})"] = len(value)
    else:
        if isinstance(value, float) and not math.isfinite(value):
            value = "nan" if math.isnan(value) else ("inf" if value > 0 else "-inf")
        out[path] = value
        if "'float32'" in repr(hint):
            f32s.append(path)


def header(sec=1700000000, nanosec=123456789, frame="base_link"):
    return Header(Time(sec, nanosec), frame)


def samples():
    """(name, message): several of each type the map can read, and the ones
    the delivery test sends."""
    inf, nan = math.inf, math.nan
    yield "scan_obstacle", LaserScan(header(frame="laser"), -1.57, 1.57, 0.01, 1e-5, 0.1, 0.05, 30.0,
                                     [2.0, 0.31, nan, inf, 1.7], [100.0, 90.5, 0.0, 0.0, 3.25])
    yield "scan_clear", LaserScan(header(frame="laser"), -3.14, 3.14, 0.1, 0.0, 0.05, 0.1, 12.0,
                                  [0.5, 3.0, inf, 11.999], [])
    yield "scan_empty", LaserScan(header(2, 0, ""), 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, [], [])
    yield "scan_long", LaserScan(header(-5, 999999999, "ü-laser"), -1.0, 1.0, 2.0 / 359, 0.0, 0.1, 0.1, 8.0,
                                 [0.1 + i * 0.0217 for i in range(360)], [float(i % 7) for i in range(360)])
    cov = [i * 0.25 - 3.0 for i in range(36)]
    for name, vx in [("odom_moving", 1.5), ("odom_stopped", 0.01), ("odom_reverse", -0.3)]:
        yield name, Odometry(header(frame="odom"), "base_footprint",
                             PoseWithCovariance(Pose(Point(1.0, -2.5, 0.0), Quaternion(0.0, 0.0, 0.38268343, 0.92387953)), cov),
                             TwistWithCovariance(Twist(Vector3(vx, 0.0, 0.0), Vector3(0.0, 0.0, 0.2)), list(reversed(cov))))
    yield "battery_low", BatteryState(header(), 11.1, 31.5, -1.25, 0.8, 5.0, 5.2, 0.15, 2, 1, 2, True,
                                      [3.7, 3.71, 3.69], [30.0, 31.0, nan], "rear", "BAT-0042")
    yield "battery_full", BatteryState(header(), 12.6, 25.0, 0.5, 4.9, 5.0, 5.2, 0.95, 4, 1, 2, True,
                                       [4.2, 4.2, 4.2, 4.19], [], "", "")
    yield "battery_absent", BatteryState(header(), nan, nan, nan, nan, nan, nan, 0.1, 0, 0, 0, False, [], [], "slot", "")
    yield "twist", Twist(Vector3(0.5, -0.1, 0.0), Vector3(0.0, 0.0, -1.2))
    yield "twist_zero", Twist()
    yield "diag_error", DiagnosticArray(header(frame=""), [
        DiagnosticStatus(2, "motor", "overcurrent", "base", [KeyValue("current", "12.5 A"), KeyValue("limit", "10 A")]),
        DiagnosticStatus(0, "lidar", "ok", "lidar", []),
    ])
    yield "diag_ok", DiagnosticArray(header(frame=""), [DiagnosticStatus(0, "motor", "", "base", [KeyValue("k", "")])])
    yield "diag_empty", DiagnosticArray(header(frame=""), [])
    yield "float64", Float64(-273.15)
    yield "float64_inf", Float64(-inf)
    yield "float32", Float32(0.1)
    yield "int32", Int32(-2147483648)
    yield "int64", Int64(9223372036854775807)
    yield "string", String("hello, situ")
    yield "string_utf8", String("grüße ✓ 機械")
    yield "string_empty", String("")
    yield "bool_true", Bool(True)
    yield "bool_false", Bool(False)
    yield "empty", Empty()
    yield "navsat", NavSatFix(header(frame="gps"), NavSatStatus(2, 1 | 8), 48.8584, 2.2945, 35.5,
                              [1.2, 0, 0, 0, 1.2, 0, 0, 0, 4.0], 2)
    yield "navsat_nofix", NavSatFix(header(frame="gps"), NavSatStatus(-1, 1), nan, nan, nan, [0.0] * 9, 0)
    yield "imu", Imu(header(frame="imu"), Quaternion(0.0, 0.0, 0.0, 1.0), [0.01, 0, 0, 0, 0.01, 0, 0, 0, 0.01],
                     Vector3(0.001, -0.002, 0.3), [-1.0] + [0.0] * 8, Vector3(0.0, 0.1, 9.81), [0.1] * 9)
    yield "range", Range(header(frame="sonar"), 0, 0.5, 0.02, 4.0, 1.234, 0.0004)
    yield "pose_stamped", PoseStamped(header(frame="map"), Pose(Point(3.0, 4.0, 0.0), Quaternion()))
    yield "state", State(3, "active")
    yield "joint_state", JointState(header(frame=""), ["shoulder", "elbow", "wrist"], [0.1, -1.2, 3.0],
                                    [0.0, 0.5, -0.25], [])
    yield "joint_state_empty", JointState(header(0, 0, ""), [], [], [], [])
    uuid = lambda k: UUID([(k * 17 + i) % 256 for i in range(16)])
    yield "goal_status", GoalStatusArray([GoalStatus(GoalInfo(uuid(1), Time(12, 5)), 2),
                                          GoalStatus(GoalInfo(uuid(9), Time(13, 0)), 6)])
    yield "goal_status_empty", GoalStatusArray([])
    yield "arm_moving", ArmStatus(header(frame="arm"), 1, [0.0, 0.5, -0.5, 1.0, 1.5, -3.0],
                                  Gripper(0.04, False, [3, -2, 1]), "suction")
    yield "arm_fault", ArmStatus(header(frame="arm"), 2, [0.0] * 6, Gripper(0.0, True, []), "")


def main():
    for name, msg in samples():
        expect, f32s = {}, []
        leaves(msg, None, "", expect, f32s)
        # Each message in both byte orders; the encapsulation header of plain
        # CDR says which: 00 01 little-endian, 00 00 big-endian.
        for suffix, order, head in [("", Endianness.Little, b"\x00\x01"), ("_be", Endianness.Big, b"\x00\x00")]:
            cdr = msg.serialize(endianness=order)
            assert cdr[:2] == head, (name, cdr[:4].hex())
            line = {"name": name + suffix, "type": full_name(msg), "cdr_hex": cdr.hex(), "expect": expect, "f32": f32s}
            print(json.dumps(line))


if __name__ == "__main__":
    main()
