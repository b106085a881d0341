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
            |(population, max_generations, crossover_ratio, w1, perception_diameter)| GaOverrides {
                population,
                max_generations,
                crossover_ratio,
                w1,
                perception_diameter,
                ..GaOverrides::default()
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
                    seed_route_used: (instance.len() % 3 != 0).then_some(instance.len() % 3 == 1),
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

/// Requests, cancels and plans without cancel tokens and the CPU budget (a peer that
/// does not know those fields) decode: the fields default to absent.
#[test]
fn messages_without_cancel_tokens_decode() {
    let cancel: CancelPlan =
        decode(br#"{"v":1,"kind":"cancel_plan","body":{"request_id":"trip-42"}}"#)
            .expect("a cancel without a token");
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
    .expect("a request without the field");
    assert_eq!((request.request_id, request.cancel_token), (None, None));
    // And a request without a token is written without the field.
    let text = String::from_utf8(encode(&CancelPlan {
        request_id: "x".into(),
        token: None,
    }))
    .expect("utf-8");
    assert!(!text.contains("token"), "{text}");
}

/// A request that does not ask for the shortest path is written without the field (a
/// planner that does not know it reads the request), and a plan without one likewise
/// (a client that does not know it reads the reply); a request without the field means
/// `omit`.
#[test]
fn the_shortest_path_fields_are_absent_unless_asked_for() {
    let request: PlanRequest = decode(
        br#"{"v":1,"kind":"plan_request","body":{"start":[0,0],"goal":[1,1],"t_exec_s":10,"deadline_s":1,"model":"model1"}}"#,
    )
    .expect("a request without the field");
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
