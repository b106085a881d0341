//! Definitions as text: a message's `.msg` lines and the `ros2msg` schema rosbag2 stores
//! for a topic.

use super::def::Base::{
    Bool, Char, Float32, Float64, Int32, Int64, Int8, Nested, Uint16, Uint32, Uint64, Uint8,
};
use super::def::{Base, Field, MsgDef, Shape};
use super::table::message;

/// How a `.msg` file names a field's type: `int8`, `geometry_msgs/Pose`, with `[36]`,
/// `[<=1]` or `[]` for arrays and sequences.
fn msg_type_text(field: &Field) -> String {
    let base = match field.base {
        Int8 => "int8".to_owned(),
        Uint8 => "uint8".to_owned(),
        Uint16 => "uint16".to_owned(),
        Int32 => "int32".to_owned(),
        Uint32 => "uint32".to_owned(),
        Int64 => "int64".to_owned(),
        Uint64 => "uint64".to_owned(),
        Float32 => "float32".to_owned(),
        Float64 => "float64".to_owned(),
        Bool => "bool".to_owned(),
        Base::String => "string".to_owned(),
        Char => "char".to_owned(),
        Nested(name) => short_name(name),
    };
    match field.shape {
        Shape::Single => base,
        Shape::Array(n) => format!("{base}[{n}]"),
        Shape::Bounded(n) => format!("{base}[<={n}]"),
        Shape::Unbounded => format!("{base}[]"),
    }
}

/// `geometry_msgs/msg/Pose` as `.msg` files and rosbag2 schemas write it:
/// `geometry_msgs/Pose`.
fn short_name(name: &str) -> String {
    match name.split('/').collect::<Vec<_>>().as_slice() {
        [package, _, short] => format!("{package}/{short}"),
        _ => name.to_owned(),
    }
}

/// The `.msg` text of one message (its fields, one a line).
pub fn msg_text(def: &MsgDef) -> String {
    def.fields
        .iter()
        .map(|field| format!("{} {}\n", msg_type_text(field), field.name))
        .collect()
}

/// Every message `name` refers to, directly or not, sorted by name and without `name`.
pub fn dependencies(name: &str) -> Vec<&'static MsgDef> {
    let mut found: Vec<&'static MsgDef> = Vec::new();
    let mut todo = vec![name.to_owned()];
    while let Some(next) = todo.pop() {
        let Some(def) = message(&next) else { continue };
        for field in def.fields {
            if let Nested(nested) = field.base {
                if nested != name && !found.iter().any(|d| d.name == nested) {
                    if let Some(dep) = message(nested) {
                        found.push(dep);
                        todo.push(nested.to_owned());
                    }
                }
            }
        }
    }
    found.sort_by_key(|d| d.name);
    found
}

/// The `ros2msg` schema rosbag2 stores for a topic of type `name`: the message's own
/// text, then each dependency after a line of 80 `=` and `MSG: pkg/Name` (the layout of
/// rosbag2's `LocalMessageDefinitionSource`, which every rosbag2 reader parses).
pub fn message_definition(name: &str) -> Option<String> {
    let def = message(name)?;
    let mut text = msg_text(def);
    for dep in dependencies(name) {
        text.push_str(&"=".repeat(80));
        text.push('\n');
        text.push_str(&format!("MSG: {}\n", short_name(dep.name)));
        text.push_str(&msg_text(dep));
    }
    Some(text)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::types::names::PATH;

    #[test]
    fn a_schema_lists_the_message_then_its_dependencies_sorted() {
        let text = message_definition(PATH).expect("Path");
        assert!(text.starts_with("std_msgs/Header header\ngeometry_msgs/PoseStamped[] poses\n"));
        let order: Vec<&str> = text
            .lines()
            .filter_map(|l| l.strip_prefix("MSG: "))
            .collect();
        assert_eq!(
            order,
            [
                "builtin_interfaces/Time",
                "geometry_msgs/Point",
                "geometry_msgs/Pose",
                "geometry_msgs/PoseStamped",
                "geometry_msgs/Quaternion",
                "std_msgs/Header"
            ]
        );
    }

    /// The `.srv` file shipped for colcon says what this table says.
    #[test]
    fn the_shipped_srv_file_matches_the_table() {
        let srv = include_str!("../../roam_interfaces/srv/PlanDowntime.srv");
        let fields = |text: &str| -> Vec<String> {
            text.lines()
                .map(|l| l.split('#').next().unwrap_or("").trim())
                .filter(|l| !l.is_empty())
                .map(|l| l.split_whitespace().take(2).collect::<Vec<_>>().join(" "))
                .collect()
        };
        let (request, response) = srv.split_once("\n---\n").expect("a --- line");
        let want = |name: &str| -> Vec<String> {
            let def = message(name).expect("defined");
            fields(&msg_text(def))
        };
        assert_eq!(
            fields(request),
            want("roam_interfaces/srv/PlanDowntime_Request")
        );
        assert_eq!(
            fields(response),
            want("roam_interfaces/srv/PlanDowntime_Response")
        );
    }
}
