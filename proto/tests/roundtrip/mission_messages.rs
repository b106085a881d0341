use super::*;
use roam_proto::mission::WindowReport;

proptest! {
    #[test]
    fn window_reports_round_trip(robot in name(), x in finite(), arrival in prop::option::of(finite()), on_time in any::<bool>()) {
        round_trips(&WindowReport { robot: robot.clone(), task: robot, window: 1, began_s: x, task_start_s: x, arrival_s: arrival, on_time, budget_s: x, planned_information: x, driven_information: x, shortest_information: x, peb_mean_m: arrival, replans: 2, replan_reasons: vec!["off_path".into()], time_model: None, late_probability: arrival, holds: 1, held_s: x, recoveries: 1, asks: vec![roam_proto::mission::AskReport { at_s: x, from: [x, x], t_exec_s: x, curious: on_time, ahead: !on_time }], asks_made: 2 });
    }
}
