//! The message catalogue: the ROS 2 message types the map may name, as data
//! (the field lines of their `.msg` definitions, constants left out), so that
//! the bridge can later derive CDR decoding from the same table.

/// Every known message: its full name and its fields, one `TYPE NAME` per line.
/// A type is a primitive, a message (`pkg/Name`, or `Name` in the same
/// package), with `[]` (unbounded array) or `[N]` (fixed array) after it.
pub const CATALOGUE: &[(&str, &str)] = &[
    ("builtin_interfaces/msg/Time", "int32 sec\nuint32 nanosec"),
    ("std_msgs/msg/Bool", "bool data"),
    ("std_msgs/msg/Int32", "int32 data"),
    ("std_msgs/msg/Int64", "int64 data"),
    ("std_msgs/msg/Float32", "float32 data"),
    ("std_msgs/msg/Float64", "float64 data"),
    ("std_msgs/msg/String", "string data"),
    ("std_msgs/msg/Empty", ""),
    ("std_msgs/msg/Header", "builtin_interfaces/Time stamp\nstring frame_id"),
    ("geometry_msgs/msg/Point", "float64 x\nfloat64 y\nfloat64 z"),
    ("geometry_msgs/msg/Quaternion", "float64 x\nfloat64 y\nfloat64 z\nfloat64 w"),
    ("geometry_msgs/msg/Vector3", "float64 x\nfloat64 y\nfloat64 z"),
    ("geometry_msgs/msg/Pose", "Point position\nQuaternion orientation"),
    ("geometry_msgs/msg/PoseWithCovariance", "Pose pose\nfloat64[36] covariance"),
    ("geometry_msgs/msg/Twist", "Vector3 linear\nVector3 angular"),
    ("geometry_msgs/msg/TwistWithCovariance", "Twist twist\nfloat64[36] covariance"),
    ("geometry_msgs/msg/PoseStamped", "std_msgs/Header header\nPose pose"),
    ("geometry_msgs/msg/TwistStamped", "std_msgs/Header header\nTwist twist"),
    (
        "sensor_msgs/msg/LaserScan",
        "std_msgs/Header header\nfloat32 angle_min\nfloat32 angle_max\nfloat32 angle_increment\n\
         float32 time_increment\nfloat32 scan_time\nfloat32 range_min\nfloat32 range_max\n\
         float32[] ranges\nfloat32[] intensities",
    ),
    (
        "sensor_msgs/msg/BatteryState",
        "std_msgs/Header header\nfloat32 voltage\nfloat32 temperature\nfloat32 current\nfloat32 charge\n\
         float32 capacity\nfloat32 design_capacity\nfloat32 percentage\nuint8 power_supply_status\n\
         uint8 power_supply_health\nuint8 power_supply_technology\nbool present\nfloat32[] cell_voltage\n\
         float32[] cell_temperature\nstring location\nstring serial_number",
    ),
    (
        "sensor_msgs/msg/Imu",
        "std_msgs/Header header\ngeometry_msgs/Quaternion orientation\nfloat64[9] orientation_covariance\n\
         geometry_msgs/Vector3 angular_velocity\nfloat64[9] angular_velocity_covariance\n\
         geometry_msgs/Vector3 linear_acceleration\nfloat64[9] linear_acceleration_covariance",
    ),
    ("sensor_msgs/msg/NavSatStatus", "int8 status\nuint16 service"),
    (
        "sensor_msgs/msg/NavSatFix",
        "std_msgs/Header header\nNavSatStatus status\nfloat64 latitude\nfloat64 longitude\nfloat64 altitude\n\
         float64[9] position_covariance\nuint8 position_covariance_type",
    ),
    (
        "sensor_msgs/msg/Range",
        "std_msgs/Header header\nuint8 radiation_type\nfloat32 field_of_view\nfloat32 min_range\n\
         float32 max_range\nfloat32 range",
    ),
    (
        "nav_msgs/msg/Odometry",
        "std_msgs/Header header\nstring child_frame_id\ngeometry_msgs/PoseWithCovariance pose\n\
         geometry_msgs/TwistWithCovariance twist",
    ),
    ("diagnostic_msgs/msg/KeyValue", "string key\nstring value"),
    (
        "diagnostic_msgs/msg/DiagnosticStatus",
        "byte level\nstring name\nstring message\nstring hardware_id\nKeyValue[] values",
    ),
    ("diagnostic_msgs/msg/DiagnosticArray", "std_msgs/Header header\nDiagnosticStatus[] status"),
    ("lifecycle_msgs/msg/State", "uint8 id\nstring label"),
    ("lifecycle_msgs/msg/Transition", "uint8 id\nstring label"),
];

/// A primitive type of ROS 2 messages.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Prim {
    Bool,
    /// An integer type (`byte`, `char`, `int8` … `uint64`).
    Int,
    /// `float32` or `float64`.
    Float,
    String,
}

/// The type of one field, with arrays and nested messages.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum FieldType {
    Prim(Prim),
    /// A message, by its full name (`geometry_msgs/msg/Pose`).
    Msg(&'static str),
    /// An array; `Some(n)` for a fixed size.
    Array(Box<FieldType>, Option<usize>),
}

/// The full name of a type as the map may write it: `pkg/msg/Name` or the
/// short `pkg/Name`; `None` if it is in neither form.
pub fn full_name(name: &str) -> Option<String> {
    let parts: Vec<&str> = name.split('/').collect();
    match parts.as_slice() {
        [pkg, "msg", n] if !pkg.is_empty() && !n.is_empty() => Some(name.to_string()),
        [pkg, n] if !pkg.is_empty() && !n.is_empty() => Some(format!("{pkg}/msg/{n}")),
        _ => None,
    }
}

/// The catalogue entry of a type named in either form.
pub fn lookup(name: &str) -> Option<&'static str> {
    let full = full_name(name)?;
    CATALOGUE.iter().find(|(n, _)| *n == full).map(|(n, _)| *n)
}

/// Every known full name.
pub fn names() -> impl Iterator<Item = &'static str> {
    CATALOGUE.iter().map(|(n, _)| *n)
}

/// The fields of a known message, in order.
pub fn fields(msg: &'static str) -> Vec<(&'static str, FieldType)> {
    let Some((_, text)) = CATALOGUE.iter().find(|(n, _)| *n == msg) else { return Vec::new() };
    let pkg = msg.split('/').next().unwrap_or("");
    text.lines()
        .filter_map(|line| {
            let (ty, name) = line.trim().split_once(' ')?;
            Some((name.trim(), parse_type(ty, pkg)?))
        })
        .collect()
}

/// The type of one field of a message, if it has that field.
pub fn field(msg: &'static str, name: &str) -> Option<FieldType> {
    fields(msg).into_iter().find(|(n, _)| *n == name).map(|(_, t)| t)
}

fn parse_type(ty: &str, pkg: &str) -> Option<FieldType> {
    if let Some(base) = ty.strip_suffix(']') {
        let (elem, size) = base.split_once('[')?;
        let size = if size.is_empty() { None } else { Some(size.parse().ok()?) };
        return Some(FieldType::Array(Box::new(parse_type(elem, pkg)?), size));
    }
    let prim = match ty {
        "bool" => Prim::Bool,
        "byte" | "char" | "int8" | "uint8" | "int16" | "uint16" | "int32" | "uint32" | "int64" | "uint64" => Prim::Int,
        "float32" | "float64" => Prim::Float,
        "string" => Prim::String,
        _ => {
            let full = if ty.contains('/') { full_name(ty)? } else { format!("{pkg}/msg/{ty}") };
            return CATALOGUE.iter().find(|(n, _)| *n == full).map(|(n, _)| FieldType::Msg(n));
        }
    };
    Some(FieldType::Prim(prim))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_field_type_resolves() {
        for (name, text) in CATALOGUE {
            let lines = text.lines().filter(|l| !l.trim().is_empty()).count();
            assert_eq!(fields(name).len(), lines, "{name}: a field type is not in the catalogue");
        }
    }

    #[test]
    fn names_in_both_forms() {
        assert_eq!(lookup("sensor_msgs/LaserScan"), Some("sensor_msgs/msg/LaserScan"));
        assert_eq!(lookup("sensor_msgs/msg/LaserScan"), Some("sensor_msgs/msg/LaserScan"));
        assert_eq!(lookup("LaserScan"), None);
        assert_eq!(lookup("a/b/c/d"), None);
    }

    #[test]
    fn laser_scan_is_exact() {
        let names: Vec<_> = fields("sensor_msgs/msg/LaserScan").into_iter().map(|(n, _)| n).collect();
        assert_eq!(
            names,
            [
                "header",
                "angle_min",
                "angle_max",
                "angle_increment",
                "time_increment",
                "scan_time",
                "range_min",
                "range_max",
                "ranges",
                "intensities"
            ]
        );
        assert_eq!(
            field("sensor_msgs/msg/LaserScan", "ranges"),
            Some(FieldType::Array(Box::new(FieldType::Prim(Prim::Float)), None))
        );
        assert_eq!(
            field("nav_msgs/msg/Odometry", "twist"),
            Some(FieldType::Msg("geometry_msgs/msg/TwistWithCovariance"))
        );
    }
}
