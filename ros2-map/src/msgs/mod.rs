//! The ROS 2 message definitions, as data: parsed from `.msg`, `.srv` and
//! `.action` files ([`idl`]), found on a search path ([`search`]: the
//! user's folders, `AMENT_PREFIX_PATH`, then the definitions situ carries
//! in `ros2-map/interfaces`), and loaded into one [`Registry`] that the
//! checks, the decoder, the evaluator and the bridge share.
//!
//! Type and field names are interned (`&'static str`, see [`intern`]): each
//! distinct name is stored once per process, however many times the
//! definitions are loaded.

pub mod idl;
pub mod registry;
pub mod search;

pub use registry::{Registry, TypeError};
pub use search::{Place, SearchPath};

use std::collections::BTreeSet;
use std::sync::Mutex;

/// A primitive type of ROS 2 messages, as expressions see it.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Prim {
    Bool,
    /// An integer type (`byte`, `char`, `int8` … `uint64`).
    Int,
    /// `float32` or `float64`.
    Float,
    /// `string` or `wstring`, bounded or not.
    String,
}

/// The type of one field, with arrays and nested messages.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum FieldType {
    Prim(Prim),
    /// A message, by its full name (`geometry_msgs/msg/Pose`).
    Msg(&'static str),
    /// An array; `Some(n)` for a fixed size (bounded arrays are `None`).
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

/// The one `&'static str` of `name` in this process: type and field names
/// are kept once, whatever the number of loads.
pub fn intern(name: &str) -> &'static str {
    static NAMES: Mutex<BTreeSet<&'static str>> = Mutex::new(BTreeSet::new());
    let mut names = NAMES.lock().unwrap_or_else(|e| e.into_inner());
    if let Some(n) = names.get(name) {
        return n;
    }
    let n: &'static str = Box::leak(name.to_string().into_boxed_str());
    names.insert(n);
    n
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_in_both_forms() {
        assert_eq!(full_name("sensor_msgs/LaserScan").as_deref(), Some("sensor_msgs/msg/LaserScan"));
        assert_eq!(full_name("sensor_msgs/msg/LaserScan").as_deref(), Some("sensor_msgs/msg/LaserScan"));
        assert_eq!(full_name("LaserScan"), None);
        assert_eq!(full_name("a/b/c/d"), None);
    }

    #[test]
    fn interned_names_are_one() {
        let a = intern(&String::from("x_intern_test"));
        let b = intern("x_intern_test");
        assert!(std::ptr::eq(a, b));
    }
}
