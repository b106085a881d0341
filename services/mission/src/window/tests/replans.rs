//! Replans while the robot drives: slack, and what a failed replan leaves (the shortest
//! path, then the window's own fastest path), and a lost mission sent again.

use super::*;

/// The robot on the curious path at 7 s, 2 m from the task: at the model's 0.5 m/s it
/// arrives at 11 s, 89 s early. Slack.
fn slack(w: &mut DowntimeWindow<'_>, mission: &Mission) -> Vec<WindowAction> {
    assert!(w
        .handle(estimate([0.1, 0.9], 0.1, 6.0), at(6.0, 0.1))
        .is_empty());
    w.handle(status(&mission.id, MissionState::Active, 2.0), at(7.0, 0.2))
}

#[test]
fn slack_replans_from_where_the_robot_will_be_while_it_drives_on() {
    let f = fixture();
    let (mut w, first) = f.driving(false);
    let actions = slack(&mut w, &first);
    // No hold: the robot drives on, and the plan starts 0.5 m (1 s at 0.5 m/s) further
    // along its route than where it is: 0.2 m north to the corner, 0.3 m east.
    assert!(!actions.iter().any(|a| matches!(a, WindowAction::Drive(_))));
    let ask = asked(&actions);
    assert!(ask.curious);
    assert!(distance(ask.from, [0.4, 1.1]) < 1e-9, "{ask:?}");
    assert!(close(ask.t_exec_s, margin().budget(92.0)));
    // Seeded with the route left from there: it starts where the plan
    // starts, follows the route, ends at the task, and runs the replan's generations.
    assert_eq!(ask.seed_route.first(), Some(&ask.from));
    assert!(ask.seed_route.len() > 2, "{ask:?}");
    let end = *ask.seed_route.last().expect("a route");
    assert!(
        distance(end, ask.to) < 0.5,
        "{end:?} is not the task {:?}",
        ask.to
    );
    let config = crate::config::ExecutiveConfig::default();
    let request = crate::request::plan_request(&config, &ask, TimeModel::table_i());
    assert_eq!(request.seed_route, ask.seed_route);
    assert_eq!(
        request.params.max_generations,
        Some(crate::config::DEFAULT_REPLAN_GENERATIONS)
    );
    let actions = answer(&mut w, curious_reply(true), at(8.0, 0.3));
    assert_eq!(
        actions[0],
        WindowAction::Replanned {
            reason: Reason::Slack
        }
    );
    assert_eq!(sent(&actions).id, "robot-tag-w0-m2");
}

/// A seeded replan costs what seeded replans cost, not what a plan costs: with the
/// same slack (the rule charges a whole plan's 1 s), a replan costing 0.2 s starts
/// 0.1 m ahead (0.2 s at 0.5 m/s) and gets the budget of 92.8 s left, not 92.
#[test]
fn a_seeded_replan_leads_and_is_budgeted_by_its_own_cost() {
    let f = fixture();
    let (mut w, first) = f.driving(false);
    let cheap = |mission_s, wall_s| Now {
        replan_cost_s: 0.2,
        ..at(mission_s, wall_s)
    };
    assert!(w
        .handle(estimate([0.1, 0.9], 0.1, 6.0), cheap(6.0, 0.1))
        .is_empty());
    let actions = w.handle(
        status(&first.id, MissionState::Active, 2.0),
        cheap(7.0, 0.2),
    );
    let ask = asked(&actions);
    assert!(ask.curious && !ask.seed_route.is_empty(), "{ask:?}");
    assert!(distance(ask.from, [0.1, 1.0]) < 1e-9, "{ask:?}");
    assert!(close(ask.t_exec_s, margin().budget(92.8)), "{ask:?}");
}

#[test]
fn no_slack_replan_near_the_windows_end() {
    let f = fixture();
    let mut setup = f.setup(0, FROM, false);
    setup.watch.min_replan_window_s = 95.0;
    let (mut w, actions) = DowntimeWindow::begin(setup, Handover::first(margin()), at(0.0, 0.0));
    assert!(asked(&actions).curious);
    let first = sent(&answer(&mut w, curious_reply(true), at(1.0, 0.0)));
    // 93 s left at 7 s: less than the 95 s a slack replan needs.
    assert!(slack(&mut w, &first).is_empty());
}

#[test]
fn a_failed_slack_replan_leaves_the_robot_on_its_path_then_the_fastest_path() {
    let f = fixture();
    let (mut w, first) = f.driving(false);
    slack(&mut w, &first);
    // The curious request fails: the shortest path is asked for, from the same place.
    let actions = answer(&mut w, failed(), at(8.0, 0.3));
    let ask = asked(&actions);
    assert!(!ask.curious);
    // That fails too: the window's own fastest path from where the robot is.
    let actions = answer(&mut w, failed(), at(8.1, 0.4));
    assert_eq!(
        actions[0],
        WindowAction::Replanned {
            reason: Reason::NoPlanner
        }
    );
    let straight = sent(&actions);
    assert_eq!(straight.id, "robot-tag-w0-m2");
    assert_eq!(
        straight.waypoints.last().copied(),
        Some(GOAL),
        "{straight:?}"
    );
    let actions = answer_status(&mut w, &straight, MissionState::Completed, at(50.0, 0.5));
    assert!(matches!(actions[0], WindowAction::Arrived { .. }));
    let r = report(&w.handle(WindowEvent::Tick, at(105.0, 0.6)));
    assert_eq!(r.replan_reasons, vec![Reason::NoPlanner.name().to_owned()]);
}

#[test]
fn a_failed_curious_replan_falls_back_to_the_shortest_path() {
    let f = fixture();
    let (mut w, _) = f.driving(false);
    let pushed = [2.0, 2.5];
    let actions = w.handle(estimate(pushed, 0.1, 3.0), at(3.0, 0.1));
    assert!(asked(&actions).curious);
    let actions = answer(&mut w, failed(), at(3.5, 0.2));
    let ask = asked(&actions);
    assert_eq!((ask.from, ask.curious), (pushed, false));
    let actions = answer(&mut w, shortest_reply(pushed), at(3.6, 0.3));
    assert_eq!(
        actions[0],
        WindowAction::Replanned {
            reason: Reason::PushedOffPath
        }
    );
    assert_eq!(
        sent(&actions).waypoints,
        mission_waypoints(&shortest_points(pushed), 1.0)
    );
}

#[test]
fn a_failed_shortest_replan_drives_the_windows_own_fastest_path() {
    let f = fixture();
    let (mut w, first) = f.driving(false);
    let actions = w.handle(status(&first.id, MissionState::Stuck, 5.0), at(4.0, 0.1));
    assert!(!asked(&actions).curious);
    let actions = answer(&mut w, failed(), at(4.1, 0.2));
    let straight = sent(&actions);
    assert_ne!(straight.id, first.id);
    // The first mission is watched no more.
    let stale = status(&first.id, MissionState::Completed, 0.0);
    assert!(w.handle(stale, at(40.0, 0.3)).is_empty());
}

#[test]
fn a_lost_mission_is_sent_again_from_where_the_robot_is() {
    let f = fixture();
    let (mut w, first) = f.driving(false);
    // The controller said nothing for 3 wall seconds.
    assert!(w.handle(WindowEvent::Tick, at(2.0, 2.9)).is_empty());
    let actions = w.handle(WindowEvent::Tick, at(2.2, 3.0));
    let ask = asked(&actions);
    assert_eq!((ask.from, ask.curious), (FROM, true));
    let actions = answer(&mut w, curious_reply(true), at(2.5, 3.1));
    assert_eq!(
        actions[0],
        WindowAction::Replanned {
            reason: Reason::ControllerSilent
        }
    );
    let again = sent(&actions);
    assert_ne!(again.id, first.id);
    let actions = w.handle(
        status(&again.id, MissionState::Completed, 0.0),
        at(50.0, 3.2),
    );
    assert!(matches!(actions[0], WindowAction::Arrived { .. }));
    let r = report(&w.handle(WindowEvent::Tick, at(105.0, 3.3)));
    assert_eq!(
        r.replan_reasons,
        vec![Reason::ControllerSilent.name().to_owned()]
    );
}

/// The robot 3 m along its curious route (1 m north, 2 m east) by its estimate made at
/// 5.5 s (heard at 6 s), when a slack replan's answer comes at 8 s: at the arrival the
/// window's drives are the replaced mission's part driven (from 1 s, when it was sent
/// with the robot standing at FROM, to the estimate's own 5.5 s, up to the route's
/// point nearest it), then the mission that arrived (to the estimate at the task).
/// After a hold on the way the replaced mission teaches nothing (that time was not
/// driving).
#[test]
fn a_replaced_mission_teaches_the_time_model_what_was_driven_unless_held() {
    let f = fixture();
    for held in [false, true] {
        let (mut w, first) = f.driving(false);
        if held {
            w.handle(
                status(&first.id, MissionState::HaltedPeb, 2.0),
                at(3.0, 0.1),
            );
        }
        assert!(w
            .handle(estimate([2.1, 1.2], 0.1, 5.5), at(6.0, 0.1))
            .is_empty());
        let actions = w.handle(status(&first.id, MissionState::Active, 2.0), at(7.0, 0.2));
        assert!(asked(&actions).curious);
        let second = sent(&answer(&mut w, curious_reply(true), at(8.0, 0.3)));
        w.handle(estimate(GOAL, 0.1, 19.5), at(19.8, 0.4));
        let actions = w.handle(
            status(&second.id, MissionState::Completed, 0.0),
            at(20.0, 0.5),
        );
        let WindowAction::Arrived { drives, .. } = &actions[0] else {
            panic!("{actions:?}");
        };
        let arrival = drives.last().expect("the arrival");
        assert_eq!(
            arrival.took_s, 14.0,
            "between the estimates, 5.5 s and 19.5 s"
        );
        if held {
            assert_eq!(drives.len(), 1, "{drives:?}");
            continue;
        }
        let [drove, _] = &drives[..] else {
            panic!("the replaced mission and the arrival: {drives:?}")
        };
        assert_eq!(drove.took_s, 4.5);
        assert_eq!(drove.path.first(), Some(&FROM));
        let end = *drove.path.last().expect("a path");
        assert!(distance(end, [2.1, 1.1]) < 1e-9, "{drove:?}");
    }
}

/// A robot that stands where its mission was sent until 3 s (the mission on its way to
/// it) is timed from then: the arrival's drive took 26 s, to the estimate at the task
/// at 29 s, of the 29 since it was sent.
#[test]
fn a_drive_is_timed_from_when_the_robot_leaves_where_it_was_sent() {
    let f = fixture();
    let (mut w, first) = f.driving(false);
    assert!(w.handle(estimate(FROM, 0.1, 2.0), at(2.0, 0.1)).is_empty());
    assert!(w
        .handle(estimate([0.11, 0.1], 0.1, 3.0), at(3.0, 0.1))
        .is_empty());
    assert!(w
        .handle(estimate([0.1, 0.5], 0.1, 4.0), at(4.0, 0.1))
        .is_empty());
    w.handle(estimate(GOAL, 0.1, 29.0), at(29.0, 0.4));
    let actions = w.handle(
        status(&first.id, MissionState::Completed, 0.0),
        at(30.0, 0.5),
    );
    let WindowAction::Arrived { drives, .. } = &actions[0] else {
        panic!("{actions:?}");
    };
    assert_eq!(drives.len(), 1, "{drives:?}");
    assert_eq!(drives[0].took_s, 26.0);
}
