//! Property tests of the codec: every message round-trips; other versions, other kinds
//! and trailing garbage are refused.

use proptest::prelude::*;
use roam_proto::cells::Cells;
use roam_proto::map::{
    CellWrite, DeleteLayer, GridMeta, Layer, LayerChange, LayerDeleted, LayerInfo, LayerList,
    LayerUpdate, LoadMap, Origin, UpdateAck,
};
use roam_proto::{decode, encode, Cause, DecodeError, ErrorCode, ErrorReply, LimitHit, Message};

fn finite() -> impl Strategy<Value = f64> {
    -1.0e6..1.0e6f64
}

fn meta() -> impl Strategy<Value = GridMeta> {
    (
        0u32..5000,
        0u32..5000,
        0.001..10.0f64,
        finite(),
        finite(),
        -3.2..3.2f64,
    )
        .prop_map(|(width, height, resolution, x, y, yaw)| GridMeta {
            width,
            height,
            resolution,
            origin: Origin { x, y, yaw },
        })
}

fn cells() -> impl Strategy<Value = Cells> {
    prop_oneof![
        prop::collection::vec(any::<i8>(), 0..300).prop_map(Cells::I8),
        prop::collection::vec(any::<u8>(), 0..300).prop_map(Cells::U8),
        prop::collection::vec(-1.0e9..1.0e9f32, 0..300).prop_map(Cells::F32),
    ]
}

fn name() -> impl Strategy<Value = String> {
    "[a-z_][a-z0-9_-]{0,20}"
}

fn layer() -> impl Strategy<Value = Layer> {
    (
        name(),
        any::<u64>(),
        meta(),
        prop::option::of(name()),
        cells(),
    )
        .prop_map(|(name, version, meta, derived_from, cells)| Layer {
            name,
            version,
            meta,
            derived_from,
            cells,
        })
}

fn info() -> impl Strategy<Value = LayerInfo> {
    layer().prop_map(|l| LayerInfo {
        name: l.name,
        version: l.version,
        meta: l.meta,
        dtype: l.cells.dtype(),
        derived_from: l.derived_from,
    })
}

fn change() -> impl Strategy<Value = LayerChange> {
    prop_oneof![
        prop::collection::vec(
            (any::<u32>(), any::<u32>(), finite()).prop_map(|(x, y, value)| CellWrite {
                x,
                y,
                value
            }),
            0..50
        )
        .prop_map(|cells| LayerChange::SetCells { cells }),
        (meta(), cells()).prop_map(|(meta, cells)| LayerChange::Replace { meta, cells }),
    ]
}

fn error_reply() -> impl Strategy<Value = ErrorReply> {
    let code = prop_oneof![
        Just(ErrorCode::Malformed),
        Just(ErrorCode::UnsupportedVersion),
        Just(ErrorCode::WrongMessage),
        Just(ErrorCode::InvalidRequest),
        Just(ErrorCode::LimitExceeded),
        Just(ErrorCode::StaleVersion),
        Just(ErrorCode::NotFound),
        Just(ErrorCode::CorruptFile),
        Just(ErrorCode::Unavailable),
        Just(ErrorCode::Busy),
        Just(ErrorCode::Internal),
    ];
    let limit = prop::option::of(
        (name(), any::<u64>(), any::<u64>()).prop_map(|(name, max, actual)| LimitHit {
            name,
            max,
            actual,
        }),
    );
    let cause = prop::option::of(prop::sample::select(vec![
        Cause::StartOffMap,
        Cause::GoalOffMap,
        Cause::StartBlocked,
        Cause::GoalBlocked,
        Cause::NoPath,
    ]));
    (code, ".{0,80}", limit, prop::option::of(0.0..1e6f64), cause).prop_map(
        |(code, message, limit, expected_wait_s, cause)| ErrorReply {
            code,
            message,
            limit,
            expected_wait_s,
            cause,
        },
    )
}

fn round_trips<T: Message + PartialEq + std::fmt::Debug>(message: &T) {
    let bytes = encode(message);
    let back: T = decode(&bytes).expect("decode what we encoded");
    assert_eq!(&back, message);
}

/// Appends garbage after a valid message and checks it is refused.
fn refuses_trailing<T: Message + std::fmt::Debug>(message: &T, garbage: &[u8]) {
    let mut bytes = encode(message);
    bytes.extend_from_slice(garbage);
    assert!(matches!(decode::<T>(&bytes), Err(DecodeError::Envelope(_))));
}

/// Rewrites the version of a valid message and checks it is refused by version.
fn refuses_version<T: Message + std::fmt::Debug>(message: &T, version: u32) {
    let mut value: serde_json::Value = serde_json::from_slice(&encode(message)).expect("json");
    value["v"] = version.into();
    let bytes = serde_json::to_vec(&value).expect("json");
    assert_eq!(
        decode::<T>(&bytes).expect_err("must be refused"),
        DecodeError::UnsupportedVersion { found: version }
    );
}

fn garbage() -> impl Strategy<Value = Vec<u8>> {
    // At least one byte that is not JSON whitespace.
    (prop::collection::vec(any::<u8>(), 0..20), any::<u8>()).prop_map(|(mut tail, first)| {
        let first = if b" \t\r\n".contains(&first) {
            b'x'
        } else {
            first
        };
        tail.insert(0, first);
        tail
    })
}

fn other_version() -> impl Strategy<Value = u32> {
    any::<u32>().prop_filter("not the current version", |v| {
        *v != roam_proto::PROTOCOL_VERSION
    })
}

proptest! {
    #[test]
    fn layer_round_trips(m in layer()) { round_trips(&m); }

    #[test]
    fn layer_list_round_trips(layers in prop::collection::vec(info(), 0..5), warnings in prop::collection::vec(".{0,30}", 0..3)) {
        round_trips(&LayerList { layers, warnings, world: None });
    }

    #[test]
    fn layer_update_round_trips(base_version in any::<u64>(), change in change()) {
        round_trips(&LayerUpdate { base_version, change, world: None });
    }

    #[test]
    fn update_ack_round_trips(layer in name(), version in any::<u64>(), derived in prop::collection::vec(info(), 0..3)) {
        round_trips(&UpdateAck { layer, version, derived });
    }

    #[test]
    fn delete_layer_round_trips(base_version in any::<u64>(), layer in name(), version in any::<u64>()) {
        round_trips(&DeleteLayer { base_version });
        round_trips(&LayerDeleted { layer, version });
    }

    #[test]
    fn load_map_round_trips(path in ".{0,60}", base_version in prop::option::of(any::<u64>())) {
        round_trips(&LoadMap { path, base_version });
    }

    #[test]
    fn error_reply_round_trips(e in error_reply()) { round_trips(&e); }

    #[test]
    fn trailing_garbage_is_refused(m in layer(), e in error_reply(), g in garbage()) {
        refuses_trailing(&m, &g);
        refuses_trailing(&e, &g);
    }

    #[test]
    fn other_versions_are_refused(m in layer(), u in change(), v in other_version()) {
        refuses_version(&m, v);
        refuses_version(&LayerUpdate { base_version: 1, change: u, world: None }, v);
    }

    #[test]
    fn arbitrary_bytes_never_panic(bytes in prop::collection::vec(any::<u8>(), 0..200)) {
        let _ = decode::<LayerUpdate>(&bytes);
        let _ = decode::<Layer>(&bytes);
    }
}

#[test]
fn a_message_sent_to_the_wrong_key_is_refused_by_kind() {
    let bytes = encode(&LoadMap {
        path: "map.yaml".into(),
        base_version: None,
    });
    let err = decode::<LayerUpdate>(&bytes).expect_err("must be refused");
    assert_eq!(err.to_reply().code, ErrorCode::WrongMessage);
    assert!(err.to_string().contains("layer_update"), "{err}");
}

#[test]
fn bad_base64_cells_are_a_body_error() {
    let bytes = br#"{"v":1,"kind":"layer_update","body":{"base_version":1,"change":{"op":"replace","meta":{"width":1,"height":1,"resolution":0.1,"origin":{"x":0,"y":0}},"cells":{"dtype":"f32","base64":"AAA="}}}}"#;
    let err = decode::<LayerUpdate>(bytes).expect_err("must be refused");
    assert_eq!(err.to_reply().code, ErrorCode::Malformed);
    assert!(err.to_string().contains("whole number"), "{err}");
}

// Each service's messages, in a file of their own.
mod controller_and_mapper_messages;
mod localization_messages;
mod mission_messages;
mod planner_messages;
mod sim_messages;
