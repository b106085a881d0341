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
