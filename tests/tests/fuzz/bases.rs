//! The valid messages each key's payloads start from, and the rewrite that keeps a
//! valid long-running request (a long sim run, a big plan) bounded.

use super::*;

pub(crate) fn meta(width: u32, height: u32, resolution: f64) -> GridMeta {
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

pub(crate) fn plan_request(start: [f64; 2], goal: [f64; 2]) -> PlanRequest {
    PlanRequest {
        request_id: None,
        cancel_token: None,
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
        shortest: roam_proto::planner::ShortestPathUse::Omit,
        seed_route: Vec::new(),
    }
}

pub(crate) fn layer_bases(occupancy_version: u64) -> Vec<Vec<u8>> {
    let set = |x, y, value| LayerUpdate {
        base_version: occupancy_version,
        change: LayerChange::SetCells {
            cells: vec![CellWrite { x, y, value }],
        },
        world: None,
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
            world: None,
        }),
        encode(&LayerUpdate {
            base_version: 0,
            change: LayerChange::Replace {
                meta: meta(4, 4, 0.5),
                cells: Cells::U8(vec![50; 16]),
            },
            world: None,
        }),
        encode(&LayerUpdate {
            base_version: 0,
            change: LayerChange::Replace {
                meta: meta(u32::MAX, u32::MAX, 1e-300),
                cells: Cells::F32(vec![f32::MAX; 4]),
            },
            world: None,
        }),
        encode(&LayerUpdate {
            base_version: 0,
            change: LayerChange::Replace {
                meta: meta(2, 2, -1.0),
                cells: Cells::I8(vec![-1, 0, 100, 127]),
            },
            world: None,
        }),
        encode(&LayerUpdate {
            base_version: 0,
            change: LayerChange::Replace {
                meta: meta(0, 0, 0.0),
                cells: Cells::I8(vec![]),
            },
            world: None,
        }),
    ]
}

/// Deletions of the layer the fuzzer's updates create (so some are accepted) or of a
/// base layer (always refused), at versions it may or may not be at.
pub(crate) fn delete_bases() -> Vec<Vec<u8>> {
    [0, 1, 2, u64::MAX]
        .iter()
        .map(|&base_version| encode(&DeleteLayer { base_version }))
        .collect()
}

pub(crate) fn load_bases() -> Vec<Vec<u8>> {
    // Never a real path: a load that succeeds replaces the map under the other
    // services (devices and FIFOs are refused, tested in the map server's own tests).
    // Paths the fuzzer makes up are mapped to a missing file below.
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

pub(crate) fn plan_bases() -> Vec<Vec<u8>> {
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
            change: None,
            obstacles: None,
        }),
        ..ok
    }));
    extremes
}

pub(crate) fn sim_bases() -> Vec<Vec<u8>> {
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

pub(crate) fn peb_bases() -> Vec<Vec<u8>> {
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
pub(crate) fn command_bases() -> Vec<Vec<u8>> {
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

pub(crate) fn ranges_bases() -> Vec<Vec<u8>> {
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

pub(crate) fn observation_bases() -> Vec<Vec<u8>> {
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

pub(crate) fn estimate_bases() -> Vec<Vec<u8>> {
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

pub(crate) fn mission_bases() -> Vec<Vec<u8>> {
    let mission = |robot: &str, waypoints: Vec<[f64; 2]>| {
        encode(&Mission {
            after_step: None,
            robot: robot.into(),
            id: "fuzz".into(),
            waypoints,
            recovery: false,
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

pub(crate) fn cancel_bases() -> Vec<Vec<u8>> {
    vec![
        encode(&CancelPlan {
            request_id: "x".into(),
            token: None,
        }),
        encode(&CancelPlan {
            request_id: "y".repeat(3000),
            token: Some("z".repeat(3000)),
        }),
    ]
}

pub(crate) fn layer_message_bases(name: &str) -> Vec<Vec<u8>> {
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

pub(crate) fn clock_bases() -> Vec<Vec<u8>> {
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
pub(crate) fn bounded(expects: Expects, bytes: Vec<u8>, robots_added: &AtomicU32) -> Vec<u8> {
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
            // A load that succeeds replaces the map under the planner, which is not
            // what this test is about.
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
