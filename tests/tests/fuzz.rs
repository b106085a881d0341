//! Bad input: every queryable and every subscriber of a running stack is fed random and
//! mutated payloads from a seeded RNG (reproducible), well over 100,000 in one bounded
//! run. No service may panic or hang, every query gets exactly one reply, a payload
//! that is not a valid request gets a structured `ErrorReply`, and afterwards every
//! service is still live and answers a normal request.

use std::collections::BTreeMap;
use std::sync::atomic::{AtomicU32, AtomicUsize, Ordering};
use std::sync::Arc;
use std::time::{Duration, Instant};

use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use roam_proto::controller::Mission;
use roam_proto::localization::{PebQuery, PebReply, PebWhere, PositionEstimate};
use roam_proto::map::{
    CellWrite, GridMeta, Layer, LayerChange, LayerList, LayerUpdate, LoadMap, Origin, UpdateAck,
};
use roam_proto::mapper::MapperStatus;
use roam_proto::planner::{CancelPlan, GaOverrides, Plan, PlanRequest, PlannerModel};
use roam_proto::sim::{
    AnchorRange, LocalObservation, NamedPoint, RangeScan, RobotCommand, SimClock, SimControl,
    SimStatus,
};
use roam_proto::{cells::Cells, decode, encode, keys, ErrorReply};
use roam_tests::{within, Harness};
use zenoh::Session;

const SEED: u64 = 0x5eed_f022;
/// Panics anywhere in this test binary (service tasks, blocking workers, Zenoh
/// callbacks): a panicking subscriber task would otherwise only stop itself.
static PANICS: AtomicUsize = AtomicUsize::new(0);
/// Queries in flight at once.
const IN_FLIGHT: usize = 32;
/// How long one query may wait for its reply (a GA plan under load is the slowest).
const QUERY_TIMEOUT: Duration = Duration::from_secs(20);

/// Which message a query key decodes, so the test knows when a refusal is required.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Expects {
    LayerUpdate,
    LoadMap,
    PlanRequest,
    SimControl,
    PebQuery,
    /// The queryable ignores the payload (index, layer get, mapper status).
    Nothing,
}

impl Expects {
    /// Whether the service must refuse `bytes` because it does not decode as its request.
    fn must_refuse(self, bytes: &[u8]) -> bool {
        match self {
            Expects::LayerUpdate => decode::<LayerUpdate>(bytes).is_err(),
            Expects::LoadMap => decode::<LoadMap>(bytes).is_err(),
            Expects::PlanRequest => decode::<PlanRequest>(bytes).is_err(),
            Expects::SimControl => decode::<SimControl>(bytes).is_err(),
            Expects::PebQuery => decode::<PebQuery>(bytes).is_err(),
            Expects::Nothing => false,
        }
    }

    /// Whether a successful reply decodes as what this key answers with.
    fn reply_decodes(self, bytes: &[u8]) -> bool {
        match self {
            Expects::LayerUpdate => decode::<UpdateAck>(bytes).is_ok(),
            Expects::LoadMap => decode::<LayerList>(bytes).is_ok(),
            Expects::PlanRequest => decode::<Plan>(bytes).is_ok(),
            Expects::SimControl => decode::<SimStatus>(bytes).is_ok(),
            Expects::PebQuery => decode::<PebReply>(bytes).is_ok(),
            Expects::Nothing => {
                decode::<LayerList>(bytes).is_ok()
                    || decode::<Layer>(bytes).is_ok()
                    || decode::<MapperStatus>(bytes).is_ok()
            }
        }
    }
}

/// One fuzzed key: where, what it decodes, valid messages to mutate, how many payloads.
struct Target {
    key: String,
    expects: Expects,
    bases: Vec<Vec<u8>>,
    count: usize,
}

// ---------------------------------------------------------------------------------------
// Payloads.

const KINDS: &[&str] = &[
    "layer",
    "layer_list",
    "layer_update",
    "update_ack",
    "load_map",
    "plan_request",
    "plan",
    "cancel_plan",
    "sim_control",
    "sim_status",
    "sim_clock",
    "robot_command",
    "range_scan",
    "observation",
    "position_estimate",
    "peb_query",
    "mission",
    "mapper_status",
    "error",
    "",
    "LAYER",
];

/// JSON values that stress a field: extremes, wrong types, NaN-like strings.
fn odd_value(rng: &mut ChaCha8Rng) -> serde_json::Value {
    use serde_json::json;
    match rng.random_range(0..26) {
        0 => json!(1e300),
        1 => json!(-1e300),
        2 => json!(f64::MAX),
        3 => json!(f64::MIN_POSITIVE),
        4 => json!(u64::MAX),
        5 => json!(i64::MIN),
        6 => json!(-1),
        7 => json!(0),
        8 => json!(u32::MAX),
        9 => json!(u64::from(u32::MAX) + 1),
        10 => json!("NaN"),
        11 => json!("inf"),
        12 => json!("-Infinity"),
        13 => json!(""),
        14 => json!("x".repeat(rng.random_range(1..4000))),
        15 => json!(null),
        16 => json!(true),
        17 => json!([]),
        18 => json!({}),
        19 => json!([1e300, -1e300]),
        20 => json!(1e-320),
        21 => json!(-0.0),
        22 => json!("../../../../etc/passwd"),
        23 => json!("a/b/*/**"),
        24 => json!(rng.random::<f64>() * 1e6 - 5e5),
        _ => json!(rng.random::<u32>()),
    }
}

/// Every JSON path (object keys and array indices) in `value`.
fn paths(value: &serde_json::Value, prefix: &mut Vec<PathStep>, out: &mut Vec<Vec<PathStep>>) {
    out.push(prefix.clone());
    match value {
        serde_json::Value::Object(map) => {
            for (k, v) in map {
                prefix.push(PathStep::Key(k.clone()));
                paths(v, prefix, out);
                prefix.pop();
            }
        }
        serde_json::Value::Array(items) => {
            // Large arrays (cells, waypoints): a few indices are enough.
            for (i, v) in items.iter().enumerate().take(8) {
                prefix.push(PathStep::Index(i));
                paths(v, prefix, out);
                prefix.pop();
            }
        }
        _ => {}
    }
}

#[derive(Debug, Clone)]
enum PathStep {
    Key(String),
    Index(usize),
}

fn at_path<'a>(
    value: &'a mut serde_json::Value,
    path: &[PathStep],
) -> Option<&'a mut serde_json::Value> {
    let mut v = value;
    for step in path {
        v = match step {
            PathStep::Key(k) => v.get_mut(k.as_str())?,
            PathStep::Index(i) => v.get_mut(*i)?,
        };
    }
    Some(v)
}

/// A JSON-aware edit: replace a field with an odd value, drop or add a field, change
/// the version or the kind, nest deeply, duplicate arrays.
fn json_edit(rng: &mut ChaCha8Rng, base: &[u8]) -> Vec<u8> {
    let Ok(mut value) = serde_json::from_slice::<serde_json::Value>(base) else {
        return base.to_vec();
    };
    match rng.random_range(0..8) {
        0 => {
            value["v"] = match rng.random_range(0..6) {
                0 => serde_json::json!(0),
                1 => serde_json::json!(2),
                2 => serde_json::json!(u32::MAX),
                3 => serde_json::json!(-1),
                4 => serde_json::json!("1"),
                _ => serde_json::json!(1.5),
            };
        }
        1 => value["kind"] = serde_json::json!(KINDS[rng.random_range(0..KINDS.len())]),
        2 => {
            if let Some(obj) = value.as_object_mut() {
                let keys: Vec<String> = obj.keys().cloned().collect();
                if !keys.is_empty() {
                    obj.remove(&keys[rng.random_range(0..keys.len())]);
                }
                if rng.random_bool(0.5) {
                    obj.insert("extra".into(), odd_value(rng));
                }
            }
        }
        3 => {
            // Deep nesting in the body.
            let depth = rng.random_range(10..200);
            let mut nested = odd_value(rng);
            for _ in 0..depth {
                nested = serde_json::json!([nested]);
            }
            value["body"] = nested;
        }
        _ => {
            let mut all = Vec::new();
            paths(&value, &mut Vec::new(), &mut all);
            let body_paths: Vec<&Vec<PathStep>> = all
                .iter()
                .filter(|p| matches!(p.first(), Some(PathStep::Key(k)) if k == "body"))
                .collect();
            if !body_paths.is_empty() {
                let path = body_paths[rng.random_range(0..body_paths.len())].clone();
                let odd = odd_value(rng);
                if let Some(slot) = at_path(&mut value, &path) {
                    if rng.random_bool(0.2) {
                        if let serde_json::Value::Object(map) = slot {
                            map.insert("unknown_field".into(), odd);
                        } else {
                            *slot = odd;
                        }
                    } else {
                        *slot = odd;
                    }
                }
            }
        }
    }
    serde_json::to_vec(&value).unwrap_or_else(|_| base.to_vec())
}

/// Byte-level mutations of a valid message.
fn mutate(rng: &mut ChaCha8Rng, base: &[u8], others: &[Vec<u8>]) -> Vec<u8> {
    let mut bytes = base.to_vec();
    let rounds = if rng.random_bool(0.7) {
        1
    } else {
        rng.random_range(2..6)
    };
    for _ in 0..rounds {
        let len = bytes.len();
        match rng.random_range(0..10) {
            0 if len > 0 => {
                for _ in 0..rng.random_range(1..8) {
                    let i = rng.random_range(0..len);
                    bytes[i] ^= 1 << rng.random_range(0..8);
                }
            }
            1 => {
                let at = rng.random_range(0..=len);
                let n = rng.random_range(1..32);
                let junk: Vec<u8> = (0..n).map(|_| rng.random()).collect();
                bytes.splice(at..at, junk);
            }
            2 if len > 0 => {
                let a = rng.random_range(0..len);
                let b = (a + rng.random_range(1..64)).min(len);
                bytes.drain(a..b);
            }
            3 => bytes.truncate(rng.random_range(0..=len)),
            4 if len > 0 => {
                const TOKENS: &[u8] = b"{}[]\",:-+.eE0123456789 \\tnf";
                let i = rng.random_range(0..len);
                bytes[i] = TOKENS[rng.random_range(0..TOKENS.len())];
            }
            5 => {
                // Digits inserted into a number: huge values.
                let at = rng.random_range(0..=len);
                let digits: Vec<u8> = (0..rng.random_range(1..25))
                    .map(|_| b'0' + rng.random_range(0..10u8))
                    .collect();
                bytes.splice(at..at, digits);
            }
            6 => bytes.extend_from_slice(
                [&b" "[..], b"x", b"{}", b"\0", b"]", b"\n\n"][rng.random_range(0..6)],
            ),
            7 if !others.is_empty() => {
                // Splice another message's tail into this one.
                let other = &others[rng.random_range(0..others.len())];
                let a = rng.random_range(0..=len);
                let b = rng.random_range(0..=other.len());
                bytes.truncate(a);
                bytes.extend_from_slice(&other[b..]);
            }
            _ => bytes = json_edit(rng, &bytes),
        }
    }
    bytes
}

/// Random bytes of random length (0..2 KiB), sometimes printable JSON-ish.
fn random_bytes(rng: &mut ChaCha8Rng) -> Vec<u8> {
    let n = rng.random_range(0..2048);
    if rng.random_bool(0.3) {
        const ALPHABET: &[u8] = b"{}[]\":,0123456789.-eEtruefalsnl vkindbody";
        (0..n)
            .map(|_| ALPHABET[rng.random_range(0..ALPHABET.len())])
            .collect()
    } else {
        (0..n).map(|_| rng.random()).collect()
    }
}

/// One payload for a target: random, a mutation of the right kind, a valid message
/// of the right kind (often extreme), or a message of another kind.
fn payload(rng: &mut ChaCha8Rng, target: &Target, all: &[Vec<u8>]) -> Vec<u8> {
    let roll = rng.random_range(0..100);
    if roll < 20 || target.bases.is_empty() {
        random_bytes(rng)
    } else if roll < 85 {
        let base = &target.bases[rng.random_range(0..target.bases.len())];
        mutate(rng, base, all)
    } else if roll < 93 {
        target.bases[rng.random_range(0..target.bases.len())].clone()
    } else {
        let other = &all[rng.random_range(0..all.len())];
        if rng.random_bool(0.5) {
            other.clone()
        } else {
            mutate(rng, other, &[])
        }
    }
}

// ---------------------------------------------------------------------------------------
// Valid messages, ordinary and extreme.

fn meta(width: u32, height: u32, resolution: f64) -> GridMeta {
    GridMeta {
        width,
        height,
        resolution,
        origin: Origin {
            x: 0.0,
            y: 0.0,
            yaw: 0.0,
        },
    }
}

fn plan_request(start: [f64; 2], goal: [f64; 2]) -> PlanRequest {
    PlanRequest {
        request_id: None,
        start,
        goal,
        t_exec_s: 80.0,
        deadline_s: 0.2,
        model: PlannerModel::Model0,
        params: GaOverrides {
            population: Some(10),
            max_generations: Some(3),
            ..GaOverrides::default()
        },
        seed: 1,
        map_version: None,
    }
}

fn layer_bases(occupancy_version: u64) -> Vec<Vec<u8>> {
    let set = |x, y, value| LayerUpdate {
        base_version: occupancy_version,
        change: LayerChange::SetCells {
            cells: vec![CellWrite { x, y, value }],
        },
    };
    vec![
        encode(&set(1, 1, 0.0)),
        encode(&set(u32::MAX, u32::MAX, 100.0)),
        encode(&set(0, 0, 1e300)),
        encode(&set(0, 0, -1e300)),
        encode(&LayerUpdate {
            base_version: u64::MAX,
            change: LayerChange::SetCells {
                cells: (0..200)
                    .map(|i| CellWrite {
                        x: i,
                        y: i,
                        value: -1.0,
                    })
                    .collect(),
            },
        }),
        encode(&LayerUpdate {
            base_version: 0,
            change: LayerChange::Replace {
                meta: meta(4, 4, 0.5),
                cells: Cells::U8(vec![50; 16]),
            },
        }),
        encode(&LayerUpdate {
            base_version: 0,
            change: LayerChange::Replace {
                meta: meta(u32::MAX, u32::MAX, 1e-300),
                cells: Cells::F32(vec![f32::MAX; 4]),
            },
        }),
        encode(&LayerUpdate {
            base_version: 0,
            change: LayerChange::Replace {
                meta: meta(2, 2, -1.0),
                cells: Cells::I8(vec![-1, 0, 100, 127]),
            },
        }),
        encode(&LayerUpdate {
            base_version: 0,
            change: LayerChange::Replace {
                meta: meta(0, 0, 0.0),
                cells: Cells::I8(vec![]),
            },
        }),
    ]
}

fn load_bases() -> Vec<Vec<u8>> {
    // Never a device or a FIFO: the map server (and the sim's `load`) reads those
    // without end today: a FIFO gets no reply and blocks a worker, /dev/zero grows
    // without bound. Paths the fuzzer makes up are mapped to a missing file below.
    [
        "/nonexistent/fuzz.yaml",
        "",
        "/",
        "/proc/self/status",
        "../config/scenarios/missing.yaml",
        "\u{0}",
    ]
    .iter()
    .flat_map(|path| {
        [
            encode(&LoadMap {
                path: (*path).into(),
                base_version: None,
            }),
            encode(&LoadMap {
                path: (*path).into(),
                base_version: Some(u64::MAX),
            }),
        ]
    })
    .collect()
}

fn plan_bases() -> Vec<Vec<u8>> {
    let ok = plan_request([-8.0, -8.0], [6.0, -7.0]);
    let shortest = PlanRequest {
        model: PlannerModel::Shortest,
        ..ok.clone()
    };
    let mut extremes = vec![encode(&ok), encode(&shortest)];
    for (t_exec, deadline) in [
        (1e300, 0.2),
        (80.0, 1e300),
        (-1.0, 0.2),
        (80.0, -1.0),
        (0.0, 0.0),
        (f64::MAX, f64::MIN_POSITIVE),
    ] {
        extremes.push(encode(&PlanRequest {
            t_exec_s: t_exec,
            deadline_s: deadline,
            ..ok.clone()
        }));
    }
    extremes.push(encode(&plan_request([1e300, -1e300], [-1e300, 1e300])));
    extremes.push(encode(&plan_request([-8.0, -8.0], [-8.0, -8.0])));
    extremes.push(encode(&PlanRequest {
        params: GaOverrides {
            population: Some(u32::MAX),
            max_generations: Some(u32::MAX),
            perception_diameter: Some(u32::MAX),
            crossover_ratio: Some(1e300),
            mutation_ratio: Some(-1.0),
            v_lin: Some(0.0),
            v_ang: Some(-0.0),
            w_loc: Some(f64::MAX),
            ..GaOverrides::default()
        },
        ..ok.clone()
    }));
    extremes.push(encode(&PlanRequest {
        request_id: Some("x".repeat(5000)),
        ..ok.clone()
    }));
    extremes.push(encode(&PlanRequest {
        request_id: Some("a/b/**".into()),
        ..ok.clone()
    }));
    extremes.push(encode(&PlanRequest {
        map_version: Some(roam_proto::planner::MapVersion {
            inflated: u64::MAX,
            information: 0,
        }),
        ..ok
    }));
    extremes
}

fn sim_bases() -> Vec<Vec<u8>> {
    [
        SimControl::Status,
        SimControl::Step { n: 1 },
        SimControl::Step { n: 0 },
        SimControl::Step { n: u32::MAX },
        SimControl::Pause,
        SimControl::Resume { rate: 1e300 },
        SimControl::Resume { rate: -1.0 },
        SimControl::Reset { seed: u64::MAX },
        SimControl::Load {
            path: "/nonexistent/scenario.yaml".into(),
            seed: 0,
        },
        SimControl::AddRobot {
            name: "fz".into(),
            at: [1e300, -1e300],
        },
        SimControl::AddRobot {
            name: "a/*".into(),
            at: [0.0, 0.0],
        },
        SimControl::RemoveRobot {
            name: "nobody".into(),
        },
    ]
    .iter()
    .map(encode)
    .collect()
}

fn peb_bases() -> Vec<Vec<u8>> {
    let q = |at: PebWhere, anchors: Option<Vec<NamedPoint>>, gradient: bool, crb: bool| {
        encode(&PebQuery {
            at,
            anchors,
            gradient,
            crb,
        })
    };
    let anchor = |name: &str, at: [f64; 2]| NamedPoint {
        name: name.into(),
        at,
    };
    vec![
        q(
            PebWhere::Points(vec![[10.0, 16.0], [35.0, 28.0]]),
            None,
            true,
            false,
        ),
        q(PebWhere::Region(meta(8, 8, 1.0)), None, false, true),
        q(
            PebWhere::Region(meta(u32::MAX, u32::MAX, 1.0)),
            None,
            false,
            true,
        ),
        q(PebWhere::Region(meta(4, 4, 0.0)), None, false, false),
        q(PebWhere::Region(meta(4, 4, -1e300)), None, false, false),
        q(PebWhere::Points(vec![]), Some(vec![]), true, true),
        q(
            PebWhere::Points(vec![[1e300, -1e300], [0.0, 0.0]]),
            Some(vec![anchor("a", [0.0, 0.0]), anchor("a", [0.0, 0.0])]),
            true,
            false,
        ),
        q(
            PebWhere::Points(vec![[5.0, 5.0]; 500]),
            Some((0..300).map(|i| anchor("n", [i as f64, 1e300])).collect()),
            true,
            false,
        ),
    ]
}

/// Subscriber messages: what the services listen to.
fn command_bases() -> Vec<Vec<u8>> {
    vec![
        encode(&RobotCommand {
            u: [0.1, 0.0],
            step: Some(1),
        }),
        encode(&RobotCommand {
            u: [1e300, -1e300],
            step: Some(u64::MAX),
        }),
        encode(&RobotCommand {
            u: [f64::MAX, f64::MIN_POSITIVE],
            step: None,
        }),
    ]
}

fn ranges_bases() -> Vec<Vec<u8>> {
    let scan = |robot: &str, ranges: Vec<AnchorRange>| {
        encode(&RangeScan {
            robot: robot.into(),
            step: 1,
            time_s: 0.1,
            ranges,
        })
    };
    let range = |anchor: &str, at: [f64; 2], range_m: f64| AnchorRange {
        anchor: anchor.into(),
        at,
        range_m,
    };
    vec![
        scan(
            "robot",
            vec![
                range("a1", [0.0, 0.0], 10.0),
                range("a2", [30.0, 0.0], 20.0),
                range("a3", [0.0, 30.0], 25.0),
            ],
        ),
        scan("robot", vec![]),
        scan(
            "robot",
            vec![
                range("a", [1e300, -1e300], -1.0),
                range("a", [0.0, 0.0], 1e300),
            ],
        ),
        scan(
            "robot",
            (0..500)
                .map(|i| range("same", [0.0, 0.0], i as f64))
                .collect(),
        ),
        scan("another", vec![range("a1", [0.0, 0.0], 0.0)]),
    ]
}

fn observation_bases() -> Vec<Vec<u8>> {
    let obs = |x0, y0, m: GridMeta, cells: Cells| {
        encode(&LocalObservation {
            robot: "robot".into(),
            step: 1,
            time_s: 0.1,
            at: [1.0, 1.0],
            x0,
            y0,
            meta: m,
            cells,
        })
    };
    vec![
        obs(
            0,
            0,
            meta(3, 3, 1.0),
            Cells::I8(vec![0, -1, 100, 0, 0, 0, 0, 0, 0]),
        ),
        obs(u32::MAX, u32::MAX, meta(3, 3, 1.0), Cells::I8(vec![100; 9])),
        obs(0, 0, meta(u32::MAX, u32::MAX, 1.0), Cells::I8(vec![0; 4])),
        obs(0, 0, meta(2, 2, 0.0), Cells::F32(vec![f32::MAX; 4])),
        obs(1, 1, meta(0, 0, -1.0), Cells::U8(vec![])),
    ]
}

fn estimate_bases() -> Vec<Vec<u8>> {
    let est = |position, crb, peb_m, degraded| {
        encode(&PositionEstimate {
            robot: "robot".into(),
            step: 1,
            time_s: 0.1,
            position,
            crb,
            peb_m,
            anchors_used: vec!["a1".into()],
            degraded,
        })
    };
    vec![
        est(
            [10.0, 16.0],
            Some([[0.01, 0.0], [0.0, 0.01]]),
            Some(0.14),
            false,
        ),
        est([1e300, -1e300], None, None, true),
        est(
            [0.0, 0.0],
            Some([[-1.0, 1e300], [1e300, -1.0]]),
            Some(-1.0),
            false,
        ),
        est(
            [f64::MAX, f64::MAX],
            Some([[0.0; 2]; 2]),
            Some(f64::MAX),
            false,
        ),
    ]
}

fn mission_bases() -> Vec<Vec<u8>> {
    let mission = |robot: &str, waypoints: Vec<[f64; 2]>| {
        encode(&Mission {
            robot: robot.into(),
            id: "fuzz".into(),
            waypoints,
        })
    };
    vec![
        mission("robot", vec![[60.0, 16.0]]),
        mission("robot", vec![]),
        mission("robot", vec![[1e300, -1e300], [f64::MAX, 0.0]]),
        mission("robot", vec![[0.0, 0.0]; 10_001]),
        mission("other", vec![[1.0, 1.0]]),
    ]
}

fn cancel_bases() -> Vec<Vec<u8>> {
    vec![
        encode(&CancelPlan {
            request_id: "x".into(),
        }),
        encode(&CancelPlan {
            request_id: "y".repeat(3000),
        }),
    ]
}

fn layer_message_bases(name: &str) -> Vec<Vec<u8>> {
    let layer = |version, m, cells| {
        encode(&Layer {
            name: name.into(),
            version,
            meta: m,
            derived_from: None,
            cells,
        })
    };
    vec![
        layer(2, meta(4, 4, 0.5), Cells::I8(vec![0; 16])),
        layer(3, meta(4, 4, 0.5), Cells::U8(vec![50; 16])),
        layer(4, meta(u32::MAX, u32::MAX, 0.5), Cells::I8(vec![0; 4])),
        layer(5, meta(2, 2, 0.0), Cells::F32(vec![f32::MAX; 4])),
        layer(6, meta(0, 0, -1.0), Cells::U8(vec![])),
    ]
}

fn clock_bases() -> Vec<Vec<u8>> {
    vec![
        encode(&SimClock {
            step: 1,
            time_s: 0.1,
        }),
        encode(&SimClock {
            step: u64::MAX,
            time_s: -1e300,
        }),
    ]
}

// ---------------------------------------------------------------------------------------
// Keeping valid-by-chance requests short, so a mutation never starts a long run.

/// Rewrites a payload that happens to be a valid request into one that cannot run for
/// long (a huge lock-step run, free-running, a long plan, a large PEB field), keeping
/// everything else as fuzzed.
fn bounded(expects: Expects, bytes: Vec<u8>, robots_added: &AtomicU32) -> Vec<u8> {
    match expects {
        Expects::SimControl => match decode::<SimControl>(&bytes) {
            Ok(SimControl::Step { n })
                if n > 20 && n <= roam_sim::service::MAX_STEPS_PER_REQUEST =>
            {
                encode(&SimControl::Step { n: u32::MAX })
            }
            Ok(SimControl::Resume { rate }) if rate.is_finite() && rate <= 1e3 => {
                encode(&SimControl::Resume { rate: 1e300 })
            }
            Ok(SimControl::AddRobot { .. })
                if robots_added.fetch_add(1, Ordering::Relaxed) >= 8 =>
            {
                encode(&SimControl::Status)
            }
            Ok(SimControl::Load { .. }) => encode(&SimControl::Load {
                path: "/nonexistent/scenario.yaml".into(),
                seed: 0,
            }),
            _ => bytes,
        },
        Expects::PlanRequest => match decode::<PlanRequest>(&bytes) {
            Ok(mut r) => {
                let mut changed = false;
                if r.deadline_s > 0.3 && r.deadline_s <= 600.0 {
                    r.deadline_s = 0.3;
                    changed = true;
                }
                if r.params.population.is_some_and(|p| p > 40 && p <= 10_000) {
                    r.params.population = Some(40);
                    changed = true;
                }
                if r.params.max_generations.unwrap_or(2000) > 10 {
                    r.params.max_generations = Some(10);
                    changed = true;
                }
                if changed {
                    encode(&r)
                } else {
                    bytes
                }
            }
            Err(_) => bytes,
        },
        Expects::PebQuery => match decode::<PebQuery>(&bytes) {
            Ok(mut q) => match &mut q.at {
                PebWhere::Region(m) if m.cell_count() > 4096 && m.cell_count() <= 1 << 26 => {
                    m.width = u32::MAX;
                    m.height = u32::MAX;
                    encode(&q)
                }
                PebWhere::Points(p) if p.len() > 2000 => {
                    p.truncate(2000);
                    encode(&q)
                }
                _ => bytes,
            },
            Err(_) => bytes,
        },
        Expects::LoadMap => match decode::<LoadMap>(&bytes) {
            // A load that succeeds replaces the map under the planner; a device or FIFO
            // path is read without end. Neither is what this test is about.
            Ok(r) if !r.path.starts_with("/nonexistent") && !r.path.is_empty() => {
                encode(&LoadMap {
                    path: "/nonexistent/fuzz.yaml".into(),
                    base_version: r.base_version,
                })
            }
            _ => bytes,
        },
        _ => bytes,
    }
}

// ---------------------------------------------------------------------------------------
// Sending.

#[derive(Debug, Default)]
struct Outcome {
    sent: usize,
    ok: usize,
    refused: usize,
    failures: Vec<String>,
}

fn show(bytes: &[u8]) -> String {
    let text = String::from_utf8_lossy(&bytes[..bytes.len().min(300)]).into_owned();
    format!("{} bytes: {text:?}", bytes.len())
}

/// One query: exactly one reply within the timeout; a refusal for a payload that is not
/// the request; a refusal that decodes as `ErrorReply`; a success that decodes.
async fn query_once(
    session: &Session,
    key: &str,
    expects: Expects,
    bytes: Vec<u8>,
) -> Result<bool, String> {
    let must_refuse = expects.must_refuse(&bytes);
    let replies = session
        .get(key)
        .payload(bytes.clone())
        .timeout(QUERY_TIMEOUT)
        .await
        .map_err(|e| format!("get on {key} failed: {e}; payload {}", show(&bytes)))?;
    let wait = QUERY_TIMEOUT + Duration::from_secs(2);
    let first = tokio::time::timeout(wait, replies.recv_async())
        .await
        .map_err(|_| format!("HANG: no reply on {key}; payload {}", show(&bytes)))?
        .map_err(|_| format!("no reply on {key}; payload {}", show(&bytes)))?;
    let refused = match first.result() {
        Ok(sample) => {
            if must_refuse {
                return Err(format!(
                    "{key} accepted a payload that is not its request; payload {}",
                    show(&bytes)
                ));
            }
            let reply = sample.payload().to_bytes();
            if !expects.reply_decodes(&reply) {
                return Err(format!(
                    "{key} replied with something undecodable ({}); payload {}",
                    show(&reply),
                    show(&bytes)
                ));
            }
            false
        }
        Err(error) => {
            let reply = error.payload().to_bytes();
            if decode::<ErrorReply>(&reply).is_err() {
                return Err(format!(
                    "{key} refused without an ErrorReply ({}); payload {}",
                    show(&reply),
                    show(&bytes)
                ));
            }
            true
        }
    };
    // The stream ends once the service has answered: a second reply is a bug.
    match tokio::time::timeout(wait, replies.recv_async()).await {
        Ok(Err(_)) => Ok(refused),
        Ok(Ok(_)) => Err(format!("a second reply on {key}; payload {}", show(&bytes))),
        Err(_) => Err(format!(
            "HANG: the query on {key} never ended; payload {}",
            show(&bytes)
        )),
    }
}

async fn storm_queries(
    session: Session,
    targets: Vec<Target>,
    all: Arc<Vec<Vec<u8>>>,
    seed: u64,
) -> BTreeMap<String, Outcome> {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let robots_added = AtomicU32::new(0);
    // Interleave the keys so every service is under load at the same time.
    let mut order: Vec<usize> = targets
        .iter()
        .enumerate()
        .flat_map(|(i, t)| std::iter::repeat_n(i, t.count))
        .collect();
    for i in (1..order.len()).rev() {
        order.swap(i, rng.random_range(0..=i));
    }
    let targets = Arc::new(targets);
    let mut outcomes: BTreeMap<String, Outcome> = BTreeMap::new();
    let mut tasks = tokio::task::JoinSet::new();
    let record = |outcomes: &mut BTreeMap<String, Outcome>,
                  (key, result): (String, Result<bool, String>)| {
        let o = outcomes.entry(key).or_default();
        match result {
            Ok(true) => o.refused += 1,
            Ok(false) => o.ok += 1,
            Err(e) => o.failures.push(e),
        }
    };
    for i in order {
        let target = &targets[i];
        let bytes = bounded(
            target.expects,
            payload(&mut rng, target, &all),
            &robots_added,
        );
        outcomes.entry(target.key.clone()).or_default().sent += 1;
        while tasks.len() >= IN_FLIGHT {
            let done = tasks.join_next().await.expect("a task").expect("no panic");
            record(&mut outcomes, done);
        }
        let (session, key, expects) = (session.clone(), target.key.clone(), target.expects);
        tasks.spawn(async move {
            let result = query_once(&session, &key, expects, bytes).await;
            (key, result)
        });
    }
    while let Some(done) = tasks.join_next().await {
        record(&mut outcomes, done.expect("no panic"));
    }
    outcomes
}

async fn storm_puts(
    session: Session,
    targets: Vec<Target>,
    all: Arc<Vec<Vec<u8>>>,
    seed: u64,
) -> BTreeMap<String, usize> {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let mut order: Vec<usize> = targets
        .iter()
        .enumerate()
        .flat_map(|(i, t)| std::iter::repeat_n(i, t.count))
        .collect();
    for i in (1..order.len()).rev() {
        order.swap(i, rng.random_range(0..=i));
    }
    let mut counts = BTreeMap::new();
    for (n, i) in order.into_iter().enumerate() {
        let target = &targets[i];
        let bytes = payload(&mut rng, target, &all);
        session.put(&target.key, bytes).await.expect("put");
        *counts.entry(target.key.clone()).or_insert(0) += 1;
        if n % 256 == 0 {
            // Let the services' subscribers run between bursts.
            tokio::task::yield_now().await;
        }
    }
    counts
}

#[tokio::test(flavor = "multi_thread", worker_threads = 4)]
async fn every_queryable_and_subscriber_survives_random_and_mutated_payloads() {
    let default_hook = std::panic::take_hook();
    std::panic::set_hook(Box::new(move |info| {
        PANICS.fetch_add(1, Ordering::SeqCst);
        default_hook(info);
    }));
    let started = Instant::now();
    let harness = Harness::start().await;
    let map_server = harness.start_map_server(harness.map_server_config()).await;
    let planner = harness.start_planner(harness.planner_config("p1")).await;
    let sim = harness.start_sim(harness.sim_config(None)).await;
    let localization = harness.start_localization(None).await;
    let controller = harness.start_controller(harness.controller_config()).await;
    let mapper = harness.start_mapper(harness.mapper_config()).await;
    let client = harness.client().await;
    let session = client.session().clone();
    let root = harness.root.clone();

    // The real planner layers, to give the planner its map back after the storm (a
    // layer publication with a higher version replaces the one it plans on).
    let inflated: Layer = within(
        "inflated",
        client.request::<Layer, Layer>(&keys::map_layer(&root, "inflated"), None),
    )
    .await
    .expect("inflated layer");
    let information: Layer = within(
        "information",
        client.request::<Layer, Layer>(&keys::map_layer(&root, "information"), None),
    )
    .await
    .expect("information layer");
    let index: LayerList = within(
        "index",
        client.request::<LayerList, LayerList>(&keys::map_index(&root), None),
    )
    .await
    .expect("index");
    let occupancy_version = index
        .layers
        .iter()
        .find(|l| l.name == "occupancy")
        .map_or(1, |l| l.version);

    let q = |key: String, expects, bases: Vec<Vec<u8>>, count| Target {
        key,
        expects,
        bases,
        count,
    };
    let queries = vec![
        q(
            keys::map_update(&root, "occupancy"),
            Expects::LayerUpdate,
            layer_bases(occupancy_version),
            3000,
        ),
        q(
            keys::map_update(&root, "fuzz"),
            Expects::LayerUpdate,
            layer_bases(0),
            2000,
        ),
        q(
            keys::map_update(&root, "inflated"),
            Expects::LayerUpdate,
            layer_bases(1),
            1000,
        ),
        q(keys::map_load(&root), Expects::LoadMap, load_bases(), 2000),
        q(keys::map_index(&root), Expects::Nothing, vec![], 1500),
        q(
            keys::map_layer(&root, "information"),
            Expects::Nothing,
            vec![],
            300,
        ),
        q(
            keys::planner_plan(&root),
            Expects::PlanRequest,
            plan_bases(),
            3500,
        ),
        q(
            keys::sim_control(&root),
            Expects::SimControl,
            sim_bases(),
            3000,
        ),
        q(
            keys::localization_peb(&root),
            Expects::PebQuery,
            peb_bases(),
            3000,
        ),
        q(keys::mapper_status(&root), Expects::Nothing, vec![], 1500),
    ];
    let puts = vec![
        q(
            keys::robot_command(&root, "robot"),
            Expects::Nothing,
            command_bases(),
            11_000,
        ),
        q(
            keys::robot_ranges(&root, "robot"),
            Expects::Nothing,
            ranges_bases(),
            11_000,
        ),
        q(
            keys::robot_observation(&root, "robot"),
            Expects::Nothing,
            observation_bases(),
            11_000,
        ),
        q(
            keys::robot_estimate(&root, "robot"),
            Expects::Nothing,
            estimate_bases(),
            11_000,
        ),
        q(
            keys::robot_mission(&root, "robot"),
            Expects::Nothing,
            mission_bases(),
            9_000,
        ),
        q(
            keys::planner_cancel(&root, "x"),
            Expects::Nothing,
            cancel_bases(),
            8_000,
        ),
        q(
            keys::map_layer(&root, "occupancy"),
            Expects::Nothing,
            layer_message_bases("occupancy"),
            3_000,
        ),
        q(
            keys::map_layer(&root, "inflated"),
            Expects::Nothing,
            layer_message_bases("inflated"),
            3_000,
        ),
        q(
            keys::map_layer(&root, "information"),
            Expects::Nothing,
            layer_message_bases("information"),
            3_000,
        ),
        q(
            keys::map_layer(&root, "peb"),
            Expects::Nothing,
            layer_message_bases("peb"),
            3_000,
        ),
        q(
            keys::sim_clock(&root),
            Expects::Nothing,
            clock_bases(),
            7_000,
        ),
    ];
    // Every valid message of every kind, for wrong-kind payloads and splices.
    let all: Arc<Vec<Vec<u8>>> = Arc::new(
        queries
            .iter()
            .chain(puts.iter())
            .flat_map(|t| t.bases.iter().cloned())
            .collect(),
    );

    let storm = Instant::now();
    let put_task = tokio::spawn(storm_puts(session.clone(), puts, all.clone(), SEED + 1));
    let query_outcomes = storm_queries(session.clone(), queries, all, SEED).await;
    let put_counts = within("puts", put_task).await.expect("no panic");
    let storm_time = storm.elapsed();

    // The report.
    let (mut total_queries, mut total_puts, mut failures) = (0, 0, Vec::new());
    for (key, o) in &query_outcomes {
        eprintln!(
            "query {key}: {} sent, {} answered, {} refused, {} failed",
            o.sent,
            o.ok,
            o.refused,
            o.failures.len()
        );
        total_queries += o.sent;
        failures.extend(o.failures.iter().take(5).cloned());
    }
    for (key, n) in &put_counts {
        eprintln!("put {key}: {n}");
        total_puts += n;
    }
    eprintln!(
        "fuzz: {total_queries} queries + {total_puts} puts = {} payloads in {:.1} s (storm {:.1} s)",
        total_queries + total_puts,
        started.elapsed().as_secs_f64(),
        storm_time.as_secs_f64()
    );
    assert!(failures.is_empty(), "failures:\n{}", failures.join("\n"));
    assert_eq!(
        PANICS.load(Ordering::SeqCst),
        0,
        "a service panicked (see the log)"
    );
    assert!(total_queries + total_puts >= 100_000);

    // Every service is still there and answers a normal request.
    for name in [
        roam_map_server::SERVICE_NAME,
        roam_planner::SERVICE_NAME,
        roam_sim::service::SERVICE_NAME,
        roam_localization::service::SERVICE_NAME,
        roam_controller::service::SERVICE_NAME,
        roam_mapper::service::SERVICE_NAME,
    ] {
        assert!(
            harness.is_live(name).await,
            "{name} lost its liveliness token"
        );
    }
    // Give the planner its real map back, above any fuzzed version.
    for mut layer in [inflated, information] {
        layer.version = u64::MAX;
        within(
            "republish",
            session.put(keys::map_layer(&root, &layer.name), encode(&layer)),
        )
        .await
        .expect("put");
    }
    let _: LayerList = within(
        "index after",
        client.request::<LayerList, LayerList>(&keys::map_index(&root), None),
    )
    .await
    .expect("the map server answers after the storm");
    let _: SimStatus = within(
        "sim after",
        client.request(&keys::sim_control(&root), Some(&SimControl::Pause)),
    )
    .await
    .expect("the sim answers after the storm");
    let _: SimStatus = within(
        "sim step after",
        client.request(&keys::sim_control(&root), Some(&SimControl::Step { n: 1 })),
    )
    .await
    .expect("the sim steps after the storm");
    let _: PebReply = within(
        "peb after",
        client.request(
            &keys::localization_peb(&root),
            Some(&PebQuery {
                at: PebWhere::Points(vec![[10.0, 16.0]]),
                anchors: None,
                gradient: false,
                crb: false,
            }),
        ),
    )
    .await
    .expect("localization answers after the storm");
    let _: MapperStatus = within(
        "mapper after",
        client.request::<MapperStatus, MapperStatus>(&keys::mapper_status(&root), None),
    )
    .await
    .expect("the mapper answers after the storm");
    // The republished map reaches the planner asynchronously.
    let until = Instant::now() + Duration::from_secs(10);
    loop {
        let plan = client
            .request::<PlanRequest, Plan>(
                &keys::planner_plan(&root),
                Some(&plan_request([-8.0, -8.0], [6.0, -7.0])),
            )
            .await;
        match plan {
            Ok(plan) => {
                assert!(!plan.points.is_empty());
                break;
            }
            Err(e) if Instant::now() < until => {
                eprintln!("plan after the storm not yet: {e}");
                tokio::time::sleep(Duration::from_millis(200)).await;
            }
            Err(e) => panic!("the planner does not plan after the storm: {e}"),
        }
    }

    // The subscribers still work: a step's ranges reach localization, whose estimate
    // reaches the controller, which takes a new mission.
    let estimates = within(
        "subscribe",
        session.declare_subscriber(keys::robot_estimate(&root, "robot")),
    )
    .await
    .expect("subscriber");
    let statuses = within(
        "subscribe",
        session.declare_subscriber(keys::robot_controller(&root, "robot")),
    )
    .await
    .expect("subscriber");
    let mission = Mission {
        robot: "robot".into(),
        id: "after-the-storm".into(),
        waypoints: vec![[60.0, 16.0]],
    };
    within(
        "mission",
        session.put(keys::robot_mission(&root, "robot"), encode(&mission)),
    )
    .await
    .expect("put");
    let stepped: SimStatus = within(
        "step",
        client.request(&keys::sim_control(&root), Some(&SimControl::Step { n: 1 })),
    )
    .await
    .expect("step");
    within("a fresh estimate", async {
        loop {
            let sample = estimates.recv_async().await.expect("sample");
            let e: PositionEstimate = decode(&sample.payload().to_bytes()).expect("estimate");
            if e.step == stepped.step {
                break;
            }
        }
    })
    .await;
    within("the new mission in a controller status", async {
        loop {
            let sample = statuses.recv_async().await.expect("sample");
            let status: roam_proto::controller::ControllerStatus =
                decode(&sample.payload().to_bytes()).expect("status");
            if status.mission.as_deref() == Some("after-the-storm") {
                break;
            }
        }
    })
    .await;
    assert_eq!(
        PANICS.load(Ordering::SeqCst),
        0,
        "a service panicked (see the log)"
    );

    // Nothing panicked: every service stops cleanly.
    for (name, service) in [
        ("mapper", mapper),
        ("controller", controller),
        ("localization", localization),
        ("sim", sim),
        ("planner", planner),
        ("map server", map_server),
    ] {
        let (_, outcome) = service.stop().await;
        assert_eq!(outcome, Ok(()), "{name} did not stop cleanly");
    }
    eprintln!(
        "fuzz: total wall time {:.1} s",
        started.elapsed().as_secs_f64()
    );
    harness.close().await;
}
