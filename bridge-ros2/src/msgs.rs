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
