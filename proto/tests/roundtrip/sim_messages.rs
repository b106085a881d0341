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
