//! RIHS01 type hashes (REP-2011), computed from the type descriptions of [`crate::types`].
//!
//! REP-2011 ("Evolving Message Types"), as `rosidl_generator_type_description` implements
//! it: the hash is `RIHS01_` and the hex SHA-256 of one JSON text,
//! `{"type_description": <T>, "referenced_type_descriptions": [<R>...]}`, where each
//! description is `{"type_name": "pkg/msg/Name", "fields": [<F>...]}` and each field
//! `{"name": ..., "type": {"type_id": ..., "capacity": ..., "string_capacity": ...,
//! "nested_type_name": ...}}`, keys in that order, the referenced types sorted by name,
//! written as Python's `json.dumps` does by default (`", "` and `": "` as separators,
//! ASCII only). Default values are not part of it, nor are comments or constants. A
//! service's description has three nested fields, `request_message`, `response_message`
//! and `event_message`, the last one rosidl's generated `<Name>_Event`
//! (`service_msgs/ServiceEventInfo info`, `<Name>_Request[<=1] request`,
//! `<Name>_Response[<=1] response`).
//!
//! Tested against the hashes ROS 2 publishes (nav_msgs/msg/OccupancyGrid, nav_msgs/msg/Path,
//! geometry_msgs/msg/PoseWithCovarianceStamped, and the service
//! example_interfaces/srv/AddTwoInts from rmw_zenoh's design document) and against
//! PyPI's `rosbags`, an independent implementation.

use sha2::{Digest, Sha256};

use crate::types::{self, Base, Field, MsgDef, Shape};

/// REP-2011's field type ids (`type_description_interfaces/msg/FieldType`): the element
/// type, plus 48 for a fixed array, 96 for a bounded and 144 for an unbounded sequence.
fn type_id(field: &OwnedField) -> u32 {
    let base = match field.base {
        Base::Nested(_) => 1,
        Base::Int8 => 2,
        Base::Uint8 => 3,
        Base::Uint16 => 5,
        Base::Int32 => 6,
        Base::Uint32 => 7,
        Base::Int64 => 8,
        Base::Uint64 => 9,
        Base::Float32 => 10,
        Base::Float64 => 11,
        // rosidl reads a `.msg` `char` as IDL `uint8` (FIELD_TYPE_UINT8), not as
        // FIELD_TYPE_CHAR: the published AddTwoInts hash, whose event message holds
        // ServiceEventInfo's `char[16] client_gid`, agrees only so.
        Base::Char => 3,
        Base::Bool => 15,
        Base::String => 17,
    };
    base + match field.shape {
        Shape::Single => 0,
        Shape::Array(_) => 48,
        Shape::Bounded(_) => 96,
        Shape::Unbounded => 144,
    }
}

/// A field of a description that may be generated (a service's event message).
#[derive(Debug, Clone)]
struct OwnedField {
    name: String,
    base: Base,
    nested: String,
    shape: Shape,
}

#[derive(Debug, Clone)]
struct Description {
    name: String,
    fields: Vec<OwnedField>,
}

impl From<&MsgDef> for Description {
    fn from(def: &MsgDef) -> Self {
        Description {
            name: def.name.to_owned(),
            fields: def.fields.iter().map(owned).collect(),
        }
    }
}

fn owned(field: &Field) -> OwnedField {
    OwnedField {
        name: field.name.to_owned(),
        base: field.base,
        nested: match field.base {
            Base::Nested(name) => name.to_owned(),
            _ => String::new(),
        },
        shape: field.shape,
    }
}

fn nested(name: &str, type_name: &str, shape: Shape) -> OwnedField {
    OwnedField {
        name: name.to_owned(),
        // The static name is not used for generated types: `nested` carries it.
        base: Base::Nested(""),
        nested: type_name.to_owned(),
        shape,
    }
}

/// Why a hash cannot be computed: a type roam does not define.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("no type description for '{0}'")]
pub struct UnknownType(pub String);

/// Appends `text` as a JSON string, ASCII only (`ensure_ascii`); type and field names are
/// identifiers and slashes, so nothing but the quotes is ever written.
fn json_string(out: &mut String, text: &str) {
    out.push('"');
    for c in text.chars() {
        match c {
            '"' => out.push_str("\\\""),
            '\\' => out.push_str("\\\\"),
            c if (' '..='~').contains(&c) => out.push(c),
            c => {
                let mut units = [0u16; 2];
                for unit in c.encode_utf16(&mut units) {
                    out.push_str(&format!("\\u{unit:04x}"));
                }
            }
        }
    }
    out.push('"');
}

fn json_description(out: &mut String, d: &Description) {
    out.push_str("{\"type_name\": ");
    json_string(out, &d.name);
    out.push_str(", \"fields\": [");
    for (i, field) in d.fields.iter().enumerate() {
        if i > 0 {
            out.push_str(", ");
        }
        let (capacity, string_capacity) = match field.shape {
            Shape::Array(n) | Shape::Bounded(n) => (n, 0),
            Shape::Single | Shape::Unbounded => (0, 0),
        };
        out.push_str("{\"name\": ");
        json_string(out, &field.name);
        out.push_str(&format!(
            ", \"type\": {{\"type_id\": {}, \"capacity\": {capacity}, \"string_capacity\": {string_capacity}, \"nested_type_name\": ",
            type_id(field)
        ));
        json_string(out, &field.nested);
        out.push_str("}}");
    }
    out.push_str("]}");
}

/// The JSON text REP-2011 hashes, for `top` and the descriptions it refers to.
fn hashable_json(top: &Description, mut referenced: Vec<Description>) -> String {
    referenced.sort_by(|a, b| a.name.cmp(&b.name));
    referenced.dedup_by(|a, b| a.name == b.name);
    let mut out = String::from("{\"type_description\": ");
    json_description(&mut out, top);
    out.push_str(", \"referenced_type_descriptions\": [");
    for (i, d) in referenced.iter().enumerate() {
        if i > 0 {
            out.push_str(", ");
        }
        json_description(&mut out, d);
    }
    out.push_str("]}");
    out
}

fn rihs01(json: &str) -> String {
    let digest = Sha256::digest(json.as_bytes());
    let hex: String = digest.iter().map(|b| format!("{b:02x}")).collect();
    format!("RIHS01_{hex}")
}

/// The RIHS01 hash of message `name` (`pkg/msg/Name`).
pub fn message_type_hash(name: &str) -> Result<String, UnknownType> {
    let def = types::message(name).ok_or_else(|| UnknownType(name.to_owned()))?;
    let referenced = types::dependencies(name)
        .into_iter()
        .map(Description::from)
        .collect();
    Ok(rihs01(&hashable_json(&Description::from(def), referenced)))
}

/// The RIHS01 hash of service `name` (`pkg/srv/Name`): of its description with the
/// request, the response and the generated event message.
pub fn service_type_hash(name: &str) -> Result<String, UnknownType> {
    let json = service_json(name)?;
    Ok(rihs01(&json))
}

fn service_json(name: &str) -> Result<String, UnknownType> {
    let request_name = format!("{name}_Request");
    let response_name = format!("{name}_Response");
    let event_name = format!("{name}_Event");
    let request = types::message(&request_name).ok_or_else(|| UnknownType(request_name.clone()))?;
    let response =
        types::message(&response_name).ok_or_else(|| UnknownType(response_name.clone()))?;
    let info = types::message(types::SERVICE_EVENT_INFO)
        .ok_or_else(|| UnknownType(types::SERVICE_EVENT_INFO.to_owned()))?;
    let event = Description {
        name: event_name.clone(),
        fields: vec![
            nested("info", types::SERVICE_EVENT_INFO, Shape::Single),
            nested("request", &request_name, Shape::Bounded(1)),
            nested("response", &response_name, Shape::Bounded(1)),
        ],
    };
    let top = Description {
        name: name.to_owned(),
        fields: vec![
            nested("request_message", &request_name, Shape::Single),
            nested("response_message", &response_name, Shape::Single),
            nested("event_message", &event_name, Shape::Single),
        ],
    };
    let mut referenced = vec![
        Description::from(request),
        Description::from(response),
        Description::from(info),
        event,
    ];
    for part in [
        request_name.as_str(),
        response_name.as_str(),
        types::SERVICE_EVENT_INFO,
    ] {
        referenced.extend(types::dependencies(part).into_iter().map(Description::from));
    }
    Ok(hashable_json(&top, referenced))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Published by ROS 2 (Jazzy's generated `*__type_support` and rmw_zenoh's keys).
    #[test]
    fn message_hashes_match_the_published_ones() {
        for (name, published) in [
            (
                types::OCCUPANCY_GRID,
                "RIHS01_8d348150c12913a31ee0ec170fbf25089e4745d17035792a1ba94d6f0bc0cfc7",
            ),
            (
                types::PATH,
                "RIHS01_1957a5bb3cee5da65c4e52e52b65a93df227efce4c20f8458b36e73066ca334b",
            ),
            (
                types::POSE_WITH_COVARIANCE_STAMPED,
                "RIHS01_26432f9803e43727d3c8f668d1fdb3c630f548af631e2f4e31382371bfea3b6e",
            ),
        ] {
            assert_eq!(message_type_hash(name).as_deref(), Ok(published), "{name}");
        }
    }

    /// rmw_zenoh's design document gives the key of example_interfaces/srv/AddTwoInts:
    /// the service construction (request, response, generated event, ServiceEventInfo's
    /// `char[16]`) reproduces its hash. The service is built here from its `.srv` text.
    #[test]
    fn the_service_construction_reproduces_add_two_ints() {
        let request = Description {
            name: "example_interfaces/srv/AddTwoInts_Request".into(),
            fields: vec![
                owned(&Field {
                    name: "a",
                    base: Base::Int64,
                    shape: Shape::Single,
                }),
                owned(&Field {
                    name: "b",
                    base: Base::Int64,
                    shape: Shape::Single,
                }),
            ],
        };
        let response = Description {
            name: "example_interfaces/srv/AddTwoInts_Response".into(),
            fields: vec![owned(&Field {
                name: "sum",
                base: Base::Int64,
                shape: Shape::Single,
            })],
        };
        let name = "example_interfaces/srv/AddTwoInts";
        let event = Description {
            name: format!("{name}_Event"),
            fields: vec![
                nested("info", types::SERVICE_EVENT_INFO, Shape::Single),
                nested("request", &request.name, Shape::Bounded(1)),
                nested("response", &response.name, Shape::Bounded(1)),
            ],
        };
        let top = Description {
            name: name.into(),
            fields: vec![
                nested("request_message", &request.name, Shape::Single),
                nested("response_message", &response.name, Shape::Single),
                nested("event_message", &event.name, Shape::Single),
            ],
        };
        let info = Description::from(types::message(types::SERVICE_EVENT_INFO).expect("info"));
        let time = Description::from(types::message(types::TIME).expect("time"));
        let json = hashable_json(&top, vec![request, response, event, info, time]);
        assert_eq!(
            rihs01(&json),
            "RIHS01_e118de6bf5eeb66a2491b5bda11202e7b68f198d6f67922cf30364858239c81a"
        );
    }

    #[test]
    fn the_json_is_python_s_default_layout() {
        let json = hashable_json(
            &Description::from(types::message(types::TIME).expect("time")),
            Vec::new(),
        );
        assert_eq!(
            json,
            "{\"type_description\": {\"type_name\": \"builtin_interfaces/msg/Time\", \"fields\": [\
             {\"name\": \"sec\", \"type\": {\"type_id\": 6, \"capacity\": 0, \"string_capacity\": 0, \"nested_type_name\": \"\"}}, \
             {\"name\": \"nanosec\", \"type\": {\"type_id\": 7, \"capacity\": 0, \"string_capacity\": 0, \"nested_type_name\": \"\"}}]}, \
             \"referenced_type_descriptions\": []}"
        );
    }

    #[test]
    fn unknown_types_are_named() {
        assert_eq!(
            message_type_hash("nav_msgs/msg/Odometry"),
            Err(UnknownType("nav_msgs/msg/Odometry".into()))
        );
        assert!(service_type_hash("nav_msgs/srv/GetMap").is_err());
    }

    #[test]
    fn the_services_hash() {
        for service in types::SERVICES {
            let hash = service_type_hash(service).expect("hash");
            assert!(
                hash.starts_with("RIHS01_") && hash.len() == 7 + 64,
                "{hash}"
            );
        }
    }
}
