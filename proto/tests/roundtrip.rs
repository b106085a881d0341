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

mod planner_messages {
    use super::*;
    use roam_proto::planner::{
        CancelPlan, FitnessTerms, GaOverrides, MapVersion, Plan, PlanProgress, PlanRequest,
        PlannerModel, ShortestPath, ShortestPathUse, StopReason,
    };

    fn shortest_use() -> impl Strategy<Value = ShortestPathUse> {
        prop_oneof![
            Just(ShortestPathUse::Omit),
            Just(ShortestPathUse::Attach),
            Just(ShortestPathUse::Fallback),
        ]
    }

    fn shortest_path() -> impl Strategy<Value = ShortestPath> {
        (
            prop::collection::vec([any::<u32>(), any::<u32>()], 0..40),
            finite(),
            finite(),
        )
            .prop_map(|(cells, t_eta_s, distinct_information)| ShortestPath {
                points: cells
                    .iter()
                    .map(|c| [f64::from(c[0]) * 0.2, f64::from(c[1]) * 0.2])
                    .collect(),
                cells,
                t_eta_s,
                distinct_information,
            })
    }

    fn model() -> impl Strategy<Value = PlannerModel> {
        prop_oneof![
            Just(PlannerModel::Shortest),
            Just(PlannerModel::Model0),
            Just(PlannerModel::Model1),
            Just(PlannerModel::Model2),
            Just(PlannerModel::Greedy),
            Just(PlannerModel::Anytime),
        ]
    }

    fn version() -> impl Strategy<Value = MapVersion> {
        (
            any::<u64>(),
            any::<u64>(),
            any::<Option<u64>>(),
            any::<Option<u64>>(),
        )
            .prop_map(|(inflated, information, change, obstacles)| MapVersion {
                inflated,
                information,
                change,
                obstacles,
            })
    }

    fn overrides() -> impl Strategy<Value = GaOverrides> {
        (
            prop::option::of(1u32..1000),
            prop::option::of(1u32..5000),
            prop::option::of(0.0..1.0f64),
            prop::option::of(finite()),
            prop::option::of(1u32..9),
        )
            .prop_map(
                |(population, max_generations, crossover_ratio, w1, perception_diameter)| {
                    GaOverrides {
                        population,
                        max_generations,
                        crossover_ratio,
                        w1,
                        perception_diameter,
                        ..GaOverrides::default()
                    }
                },
            )
    }

    fn request() -> impl Strategy<Value = PlanRequest> {
        (
            (prop::option::of(name()), prop::option::of(name())),
            [finite(), finite()],
            [finite(), finite()],
            (finite(), finite()),
            model(),
            overrides(),
            any::<u64>(),
            prop::option::of(version()),
            shortest_use(),
            prop::collection::vec([finite(), finite()], 0..4),
        )
            .prop_map(
                |(
                    (request_id, cancel_token),
                    start,
                    goal,
                    (t_exec_s, deadline_s),
                    model,
                    params,
                    seed,
                    map_version,
                    shortest,
                    seed_route,
                )| PlanRequest {
                    request_id,
                    cancel_token,
                    start,
                    goal,
                    t_exec_s,
                    deadline_s,
                    model,
                    params,
                    seed,
                    map_version,
                    shortest,
                    seed_route,
                },
            )
    }

    fn plan() -> impl Strategy<Value = Plan> {
        (
            name(),
            model(),
            prop::collection::vec([any::<u32>(), any::<u32>()], 0..40),
            (finite(), any::<bool>(), any::<bool>()),
            [finite(), finite(), finite(), finite(), finite(), finite()],
            (finite(), finite(), finite(), any::<u32>(), finite()),
            prop_oneof![
                Just(StopReason::MaxGenerations),
                Just(StopReason::Deadline),
                Just(StopReason::Cancelled),
                Just(StopReason::CpuGrant),
                Just(StopReason::Complete)
            ],
            (any::<u64>(), version(), name(), prop::option::of(finite())),
            prop::option::of(shortest_path()),
        )
            .prop_map(
                |(
                    request_id,
                    model,
                    cells,
                    (t_eta_s, reaches_goal, within_budget),
                    f,
                    (u_ges, density, distinct_information, generations, planning_ms),
                    stop_reason,
                    (seed, map_version, instance, cpu_grant_s),
                    shortest,
                )| {
                    let points = cells
                        .iter()
                        .map(|c| [f64::from(c[0]) * 0.2, f64::from(c[1]) * 0.2])
                        .collect();
                    Plan {
                        request_id,
                        model,
                        cells,
                        points,
                        t_eta_s,
                        reaches_goal,
                        within_budget,
                        fitness: FitnessTerms {
                            f1_information: f[0],
                            f2_on_time: f[1],
                            f3_goal: f[2],
                            f4_overtime: f[3],
                            f5_idle: f[4],
                            f6_localizability: -f[0],
                            total: f[5],
                        },
                        u_ges,
                        density,
                        distinct_information,
                        generations,
                        planning_ms,
                        stop_reason,
                        planning_resolution_m: cpu_grant_s.map(f64::abs),
                        cpu_grant_s,
                        seed,
                        map_version,
                        found_by: instance.is_empty().then(|| "greedy".to_owned()),
                        seed_route_used: (instance.len() % 3 != 0)
                            .then_some(instance.len() % 3 == 1),
                        instance,
                        shortest,
                    }
                },
            )
    }

    proptest! {
        #[test]
        fn plan_request_round_trips(m in request()) { round_trips(&m); }

        /// A plan written with the CPU grant's old names (`stop_reason: budget`,
        /// `budget_s`) reads as the same plan.
        #[test]
        fn a_plan_under_the_cpu_grants_old_names_reads_the_same(m in plan()) {
            let mut value = serde_json::to_value(&m).expect("json");
            let object = value.as_object_mut().expect("an object");
            if let Some(grant) = object.remove("cpu_grant_s") {
                object.insert("budget_s".into(), grant);
            }
            if object.get("stop_reason") == Some(&serde_json::json!("cpu_grant")) {
                object.insert("stop_reason".into(), serde_json::json!("budget"));
            }
            let read: Plan = serde_json::from_value(value).expect("read");
            prop_assert_eq!(read, m);
        }

        #[test]
        fn plan_round_trips(m in plan()) {
            round_trips(&m);
            // A client that did not ask for the shortest path never sees the field.
            let text = String::from_utf8(encode(&m)).expect("utf-8");
            prop_assert_eq!(text.contains(r#""shortest":"#), m.shortest.is_some());
        }

        #[test]
        fn progress_and_cancel_round_trip(id in name(), best in prop::collection::vec((any::<u32>(), finite()), 0..20), done in any::<bool>()) {
            round_trips(&PlanProgress { request_id: id.clone(), best_fitness: best, done });
            round_trips(&CancelPlan { request_id: id.clone(), token: None });
            round_trips(&CancelPlan { request_id: id.clone(), token: Some(id) });
        }

        #[test]
        fn planner_messages_refuse_garbage_and_versions(m in request(), g in garbage(), v in other_version()) {
            refuses_trailing(&m, &g);
            refuses_version(&m, v);
        }
    }

    /// Requests, cancels and plans written before cancel tokens and the CPU budget
    /// still decode: the new fields default to absent.
    #[test]
    fn messages_from_before_cancel_tokens_still_decode() {
        let cancel: CancelPlan =
            decode(br#"{"v":1,"kind":"cancel_plan","body":{"request_id":"trip-42"}}"#)
                .expect("an old cancel");
        assert_eq!(
            cancel,
            CancelPlan {
                request_id: "trip-42".into(),
                token: None
            }
        );
        let request: PlanRequest = decode(
            br#"{"v":1,"kind":"plan_request","body":{"start":[0,0],"goal":[1,1],"t_exec_s":10,"deadline_s":1,"model":"model1"}}"#,
        )
        .expect("an old request");
        assert_eq!((request.request_id, request.cancel_token), (None, None));
        // And a request without a token is written without the field.
        let text = String::from_utf8(encode(&CancelPlan {
            request_id: "x".into(),
            token: None,
        }))
        .expect("utf-8");
        assert!(!text.contains("token"), "{text}");
    }

    /// A request that does not ask for the shortest path is written as before the field
    /// (so a planner from before it reads it), and a plan without one likewise (so a
    /// client from before it reads the reply); an old request means `omit`.
    #[test]
    fn the_shortest_path_fields_are_absent_unless_asked_for() {
        let request: PlanRequest = decode(
            br#"{"v":1,"kind":"plan_request","body":{"start":[0,0],"goal":[1,1],"t_exec_s":10,"deadline_s":1,"model":"model1"}}"#,
        )
        .expect("an old request");
        assert_eq!(request.shortest, ShortestPathUse::Omit);
        let text = String::from_utf8(encode(&request)).expect("utf-8");
        assert!(!text.contains("shortest"), "{text}");
        let fallback = PlanRequest {
            shortest: ShortestPathUse::Fallback,
            ..request
        };
        let text = String::from_utf8(encode(&fallback)).expect("utf-8");
        assert!(text.contains(r#""shortest":"fallback""#), "{text}");
        let refused = decode::<PlanRequest>(
            br#"{"v":1,"kind":"plan_request","body":{"start":[0,0],"goal":[1,1],"t_exec_s":10,"deadline_s":1,"model":"model1","shortest":"sometimes"}}"#,
        );
        assert!(refused.is_err(), "{refused:?}");
    }
}

mod sim_messages {
    use super::*;
    use roam_proto::sim::{
        AnchorRange, GroundTruth, LocalObservation, NamedPoint, PendingCommand, RangeScan,
        RobotCommand, RobotEventKind, RobotEvents, SimClock, SimControl, SimStatus,
    };

    fn point() -> impl Strategy<Value = [f64; 2]> {
        [finite(), finite()]
    }

    fn control() -> impl Strategy<Value = SimControl> {
        prop_oneof![
            (".{0,40}", any::<u64>()).prop_map(|(path, seed)| SimControl::Load { path, seed }),
            any::<u64>().prop_map(|seed| SimControl::Reset { seed }),
            any::<u32>().prop_map(|n| SimControl::Step { n }),
            Just(SimControl::Pause),
            (0.0..100.0f64).prop_map(|rate| SimControl::Resume { rate }),
            (name(), point()).prop_map(|(name, at)| SimControl::AddRobot { name, at }),
            name().prop_map(|name| SimControl::RemoveRobot { name }),
            Just(SimControl::Status),
        ]
    }

    fn event() -> impl Strategy<Value = RobotEventKind> {
        prop_oneof![
            (finite(), finite()).prop_map(|(requested_m, allowed_m)| {
                RobotEventKind::SpeedClipped {
                    requested_m,
                    allowed_m,
                }
            }),
            (point(), point(), any::<[i64; 2]>(), name()).prop_map(
                |(target, stopped_at, cell, obstacle)| RobotEventKind::Collision {
                    target,
                    stopped_at,
                    cell,
                    obstacle
                }
            ),
            (point(), point(), name()).prop_map(|(from, to, by)| RobotEventKind::Displaced {
                from,
                to,
                by
            }),
            name().prop_map(|by| RobotEventKind::Trapped { by }),
        ]
    }

    proptest! {
        #[test]
        fn control_round_trips(m in control()) { round_trips(&m); }

        #[test]
        fn status_and_clock_round_trip(scenario in name(), seed in any::<u64>(), step in any::<u64>(), time_s in finite(), running in any::<bool>(), robots in prop::collection::vec((name(), point()), 0..4)) {
            let robots: Vec<NamedPoint> = robots.into_iter().map(|(name, at)| NamedPoint { name, at }).collect();
            round_trips(&SimStatus { scenario, seed, step, time_s, running, rate: 1.0, step_s: 0.1, late_steps: 1, free_steps: 9, anchors: robots.clone(), robots, pending: vec![PendingCommand { robot: "r1".into(), step: Some(step) }] });
            round_trips(&SimClock { step, time_s });
        }

        #[test]
        fn sensor_messages_round_trip(robot in name(), step in any::<u64>(), time_s in finite(), u in point(), ranges in prop::collection::vec((name(), point(), finite()), 0..6), m in meta(), cells in prop::collection::vec(any::<i8>(), 0..50), events in prop::collection::vec(event(), 0..4)) {
            round_trips(&RobotCommand { u, step: Some(step) });
            round_trips(&RobotCommand { u, step: None });
            round_trips(&RangeScan { robot: robot.clone(), step, time_s, ranges: ranges.into_iter().map(|(anchor, at, range_m)| AnchorRange { anchor, at, range_m }).collect() });
            round_trips(&LocalObservation { robot: robot.clone(), step, time_s, at: u, x0: 3, y0: 4, meta: m, cells: Cells::I8(cells) });
            round_trips(&GroundTruth { robot: robot.clone(), step, time_s, at: u });
            round_trips(&RobotEvents { robot, step, events });
        }

        #[test]
        fn sim_messages_refuse_garbage_and_versions(m in control(), g in garbage(), v in other_version()) {
            refuses_trailing(&m, &g);
            refuses_version(&m, v);
        }
    }
}

mod localization_messages {
    use super::*;
    use roam_proto::localization::{PebAt, PebQuery, PebReply, PebWhere, PositionEstimate};
    use roam_proto::sim::NamedPoint;

    fn matrix() -> impl Strategy<Value = [[f64; 2]; 2]> {
        [[finite(), finite()], [finite(), finite()]]
    }

    proptest! {
        #[test]
        fn estimate_round_trips(robot in name(), step in any::<u64>(), p in [finite(), finite()], crb in prop::option::of(matrix()), peb in prop::option::of(0.0..1e3f64), used in prop::collection::vec(name(), 0..5), degraded in any::<bool>()) {
            round_trips(&PositionEstimate { robot, step, time_s: 1.5, position: p, crb, peb_m: peb, anchors_used: used, degraded });
        }

        #[test]
        fn peb_query_and_reply_round_trip(points in prop::collection::vec([finite(), finite()], 0..8), m in meta(), anchors in prop::option::of(prop::collection::vec((name(), [finite(), finite()]), 0..4)), gradient in any::<bool>(), cells in prop::collection::vec(0.0..100.0f32, 0..30)) {
            let anchors = anchors.map(|a| a.into_iter().map(|(name, at)| NamedPoint { name, at }).collect());
            round_trips(&PebQuery { at: PebWhere::Points(points.clone()), anchors: anchors.clone(), gradient, crb: false });
            round_trips(&PebQuery { at: PebWhere::Region(m), anchors, gradient: false, crb: gradient });
            round_trips(&PebReply::Points(points.iter().map(|&at| PebAt { at, peb_m: Some(1.0), crb: None, gradient: Some([0.1, -0.2]) }).collect()));
            round_trips(&PebReply::Field { meta: m, cells: Cells::F32(cells.clone()), crb: None });
            round_trips(&PebReply::Field { meta: m, cells: Cells::F32(cells.clone()), crb: Some(roam_proto::localization::CrbCells { xx: Cells::F32(cells.clone()), xy: Cells::F32(cells.clone()), yy: Cells::F32(cells) }) });
        }
    }
}

mod controller_and_mapper_messages {
    use super::*;
    use roam_proto::controller::{ControllerStatus, Mission, MissionState};
    use roam_proto::mapper::{ExplorationGoal, ExplorerStatus, MapperStatus, ReservationStatus};

    fn state() -> impl Strategy<Value = MissionState> {
        prop_oneof![
            Just(MissionState::Idle),
            Just(MissionState::Active),
            Just(MissionState::Completed),
            Just(MissionState::Stuck),
            Just(MissionState::HaltedPeb),
            Just(MissionState::HaltedStale),
            Just(MissionState::StepLimit),
        ]
    }

    proptest! {
        #[test]
        fn controller_messages_round_trip(id in name(), waypoints in prop::collection::vec([finite(), finite()], 0..6), state in state(), steps in any::<u64>(), peb in prop::option::of(finite()), x in finite()) {
            let mission = Mission { after_step: None, robot: id.clone(), id: id.clone(), waypoints, recovery: false };
            round_trips(&mission);
            round_trips(&ControllerStatus { robot: id.clone(), mission: Some(id), state, waypoint: Some(2), waypoints: 5, distance_left_m: Some(x), steps, estimate_step: Some(steps), peb_m: peb, omega_deg: x, z_isa: x, u: [x, x] });
        }

        #[test]
        fn mapper_messages_round_trip(robot in name(), step in any::<u64>(), x in finite(), goal in prop::option::of([finite(), finite()])) {
            round_trips(&ExplorationGoal { robot: robot.clone(), step, time_s: x, goal: [x, x], strategy: "poisson".into(), episodes: step });
            round_trips(&MapperStatus { observations: step, map_changes: step, p: x, r: x, layers_sent: 3, explorers: vec![ExplorerStatus { robot: robot.clone(), strategy: None, goal, episodes: 1 }], reservations: vec![ReservationStatus { robot, cells: step }] });
        }

        #[test]
        fn controller_messages_refuse_garbage_and_versions(id in name(), g in garbage(), v in other_version()) {
            let m = Mission { after_step: None, robot: id.clone(), id, waypoints: vec![[1.0, 2.0]], recovery: false };
            refuses_trailing(&m, &g);
            refuses_version(&m, v);
        }
    }
}

mod mission_messages {
    use super::*;
    use roam_proto::mission::WindowReport;

    proptest! {
        #[test]
        fn window_reports_round_trip(robot in name(), x in finite(), arrival in prop::option::of(finite()), on_time in any::<bool>()) {
            round_trips(&WindowReport { robot: robot.clone(), task: robot, window: 1, began_s: x, task_start_s: x, arrival_s: arrival, on_time, budget_s: x, planned_information: x, driven_information: x, shortest_information: x, peb_mean_m: arrival, replans: 2, replan_reasons: vec!["off_path".into()], time_model: None, late_probability: arrival, holds: 1, held_s: x, recoveries: 1, asks: vec![roam_proto::mission::AskReport { at_s: x, from: [x, x], t_exec_s: x, curious: on_time, ahead: !on_time }], asks_made: 2 });
        }
    }
}
