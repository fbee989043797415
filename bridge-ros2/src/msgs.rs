//! The ROS 2 messages the bridge writes or exchanges with lifecycle nodes,
//! as serde types whose CDR encoding is ROS 2's (field order and widths of
//! the `.msg` and `.srv` definitions).

use serde::{Deserialize, Serialize};

/// `builtin_interfaces/msg/Time`.
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize, Deserialize)]
pub struct Time {
    pub sec: i32,
    pub nanosec: u32,
}

impl Time {
    /// The time of `ns` nanoseconds since the Unix epoch.
    pub fn from_nanos(ns: u64) -> Time {
        Time { sec: (ns / 1_000_000_000).min(i32::MAX as u64) as i32, nanosec: (ns % 1_000_000_000) as u32 }
    }
}

/// `std_msgs/msg/Header`.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct Header {
    pub stamp: Time,
    pub frame_id: String,
}

/// `geometry_msgs/msg/Point`.
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize, Deserialize)]
pub struct Point {
    pub x: f64,
    pub y: f64,
    pub z: f64,
}

/// `geometry_msgs/msg/Quaternion`.
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize, Deserialize)]
pub struct Quaternion {
    pub x: f64,
    pub y: f64,
    pub z: f64,
    pub w: f64,
}

/// `geometry_msgs/msg/Pose`.
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize, Deserialize)]
pub struct Pose {
    pub position: Point,
    pub orientation: Quaternion,
}

/// `geometry_msgs/msg/PoseStamped` (what the tests and the benchmark publish).
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct PoseStamped {
    pub header: Header,
    pub pose: Pose,
}

/// `sensor_msgs/msg/LaserScan` (what the tests and the benchmark publish).
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct LaserScan {
    pub header: Header,
    pub angle_min: f32,
    pub angle_max: f32,
    pub angle_increment: f32,
    pub time_increment: f32,
    pub scan_time: f32,
    pub range_min: f32,
    pub range_max: f32,
    pub ranges: Vec<f32>,
    pub intensities: Vec<f32>,
}

/// A message's CDR bytes as ROS 2 sends them: the little-endian
/// encapsulation header, then the fields.
pub fn to_cdr<T: Serialize>(msg: &T) -> Result<Vec<u8>, rustdds::cdr_encoding::Error> {
    let mut bytes = vec![0, 1, 0, 0];
    bytes.extend(rustdds::cdr_encoding::to_vec::<T, byteorder::LittleEndian>(msg)?);
    Ok(bytes)
}

/// `std_msgs/msg/String`.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct StringMsg {
    pub data: String,
}

/// `diagnostic_msgs/msg/KeyValue`.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct KeyValue {
    pub key: String,
    pub value: String,
}

/// `diagnostic_msgs/msg/DiagnosticStatus`.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct DiagnosticStatus {
    /// `OK` 0, `WARN` 1, `ERROR` 2, `STALE` 3.
    pub level: u8,
    pub name: String,
    pub message: String,
    pub hardware_id: String,
    pub values: Vec<KeyValue>,
}

/// The levels of [`DiagnosticStatus`].
pub mod level {
    pub const OK: u8 = 0;
    pub const WARN: u8 = 1;
    pub const ERROR: u8 = 2;
}

/// `diagnostic_msgs/msg/DiagnosticArray`.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct DiagnosticArray {
    pub header: Header,
    pub status: Vec<DiagnosticStatus>,
}

/// `lifecycle_msgs/msg/Transition`.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct Transition {
    pub id: u8,
    pub label: String,
}

/// `lifecycle_msgs/msg/State`.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct State {
    pub id: u8,
    pub label: String,
}

/// `lifecycle_msgs/srv/ChangeState` request.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct ChangeStateRequest {
    pub transition: Transition,
}
impl ros2_client::Message for ChangeStateRequest {}

/// `lifecycle_msgs/srv/ChangeState` response.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct ChangeStateResponse {
    pub success: bool,
}
impl ros2_client::Message for ChangeStateResponse {}

/// `lifecycle_msgs/srv/GetState` request (no field: CDR needs one byte of
/// padding for an empty structure, as rosidl generates).
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct GetStateRequest {
    pub structure_needs_at_least_one_member: u8,
}
impl ros2_client::Message for GetStateRequest {}

/// `lifecycle_msgs/srv/GetState` response.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct GetStateResponse {
    pub current_state: State,
}
impl ros2_client::Message for GetStateResponse {}
