//! A window from its first plan to its end: the plan asked and sent, the shortest path
//! when the curious one does not fit or no time is left, estimates heard, arrival,
//! giving up, a stuck robot, a task over before its window.

use super::*;

#[test]
fn the_first_plan_is_asked_for_then_sent_as_a_mission() {
    let f = fixture();
    let (mut w, actions) = f.begin(false);
    // 100 s to the task, minus the plan's 1 s, minus the margin.
    let ask = asked(&actions);
    assert_eq!(actions.len(), 1);
    assert_eq!((ask.from, ask.to, ask.curious), (FROM, GOAL, true));
    assert!(close(ask.t_exec_s, margin().budget(99.0)), "{ask:?}");
    let actions = answer(&mut w, curious_reply(true), at(1.0, 0.0));
    assert_eq!(
        actions[0],
        WindowAction::Planned {
            budget_s: margin().budget(99.0),
            eta_s: CURIOUS_ETA_S,
            curious: true,
            late_probability: margin().late_probability(CURIOUS_ETA_S, 99.0),
        }
    );
    let mission = sent(&actions);
    assert_eq!(mission.id, "robot-tag-w0-m1");
    assert_eq!(mission.robot, "robot");
    assert_eq!(
        mission.waypoints,
        mission_waypoints(&curious_points(), 1.0),
        "every turn kept"
    );
    assert_eq!(actions.len(), 2);
}

#[test]
fn a_plan_that_does_not_fit_drives_the_shortest_path_it_carries() {
    let f = fixture();
    // The GA's path over its budget: the attached shortest path is driven.
    let (mut w, _) = f.begin(false);
    let actions = answer(&mut w, curious_reply(false), at(1.0, 0.0));
    assert!(matches!(
        actions[0],
        WindowAction::Planned { curious: false, eta_s, .. } if eta_s == SHORTEST_ETA_S
    ));
    assert_eq!(
        sent(&actions).waypoints,
        mission_waypoints(&shortest_points(FROM), 1.0)
    );
    // The planner's fallback for a budget the shortest path does not fit.
    let (mut w, _) = f.begin(false);
    let actions = answer(&mut w, shortest_reply(FROM), at(1.0, 0.0));
    assert!(matches!(
        actions[0],
        WindowAction::Planned { curious: false, .. }
    ));
    // A curious reply without the shortest path (a planner that did not attach it)
    // cannot be compared or fallen back from: asked again, as a failure.
    let (mut w, _) = f.begin(false);
    let bare = reply(plan(PlannerModel::Model1, curious_points(), CURIOUS_ETA_S));
    assert!(answer(&mut w, bare, at(1.0, 0.0)).is_empty());
    let again = w.handle(WindowEvent::Tick, at(1.2, PLAN_RETRY_S));
    assert!(asked(&again).curious);
}

#[test]
fn a_window_without_time_left_asks_for_the_shortest_path() {
    let f = fixture();
    let (_, actions) = DowntimeWindow::begin(
        f.setup(0, FROM, false),
        Handover::first(margin()),
        at(99.5, 0.0),
    );
    let ask = asked(&actions);
    assert!(!ask.curious, "{ask:?}");
    assert!(
        ask.t_exec_s > 0.0,
        "the planner takes only positive budgets"
    );
}

#[test]
fn estimates_are_recorded_and_fed_to_the_watch() {
    let f = fixture();
    let (mut w, _) = f.driving(false);
    let on_path = [0.1, 0.5];
    assert!(w
        .handle(estimate(on_path, 0.2, 2.0), at(2.0, 0.1))
        .is_empty());
    // A degraded estimate is neither recorded nor watched, however far off.
    let degraded = WindowEvent::Estimate {
        position: [3.9, 3.9],
        peb_m: Some(9.0),
        degraded: true,
        time_s: 2.5,
    };
    assert!(w.handle(degraded, at(2.5, 0.2)).is_empty());
    // Pushed off the path: a curious replan from where the robot is.
    let pushed = [2.0, 2.5];
    let actions = w.handle(estimate(pushed, 0.4, 3.0), at(3.0, 0.3));
    let ask = asked(&actions);
    assert_eq!((ask.from, ask.curious), (pushed, true));
    assert!(close(ask.t_exec_s, margin().budget(96.0)), "{ask:?}");
    // While the plan is being made, estimates are recorded, nothing is decided.
    let waiting = [2.0, 2.7];
    assert!(w
        .handle(estimate(waiting, 0.6, 3.1), at(3.1, 0.3))
        .is_empty());
    assert!(w.handle(WindowEvent::Tick, at(3.2, 9.0)).is_empty());
    let route = line(pushed, [2.0, 0.1]);
    let reply = reply(Plan {
        shortest: attached(route.clone()),
        ..plan(PlannerModel::Model1, route, 10.0)
    });
    let actions = answer(&mut w, reply, at(4.0, 0.4));
    assert_eq!(
        actions[0],
        WindowAction::Replanned {
            reason: Reason::PushedOffPath
        }
    );
    let mission = sent(&actions);
    let done = w.handle(
        status(&mission.id, MissionState::Completed, 0.0),
        at(60.0, 1.0),
    );
    assert!(matches!(done[0], WindowAction::Arrived { .. }));
    let r = report(&w.handle(WindowEvent::Tick, at(105.0, 2.0)));
    assert_eq!(
        r.driven_information,
        f.scale().of(&[FROM, on_path, pushed, waiting])
    );
    assert!(close(r.peb_mean_m.expect("pebs"), 0.4), "{r:?}");
}

#[test]
fn arrival_ends_the_window_with_its_report_when_the_task_ends() {
    let f = fixture();
    let (mut w, mission) = f.driving(false);
    // Statuses on another mission are not about this one.
    let other = status("robot-old-w0-m7", MissionState::Completed, 0.0);
    assert!(w.handle(other, at(20.0, 0.1)).is_empty());
    // Seen at the task by the estimate made at 79.6 s, heard of arriving at 80 s: the
    // calibration learns the drive up to the estimate (the margin up to 80 s).
    assert!(w
        .handle(estimate(GOAL, 0.1, 79.6), at(79.8, 0.15))
        .is_empty());
    let actions = w.handle(
        status(&mission.id, MissionState::Completed, 0.0),
        at(80.0, 0.2),
    );
    let path: Vec<[f64; 2]> = std::iter::once(FROM).chain(curious_points()).collect();
    assert_eq!(
        actions,
        vec![WindowAction::Arrived {
            at_s: 80.0,
            drives: vec![DrivenMission {
                path: path.clone(),
                took_s: 78.6
            }]
        }],
        "no next task: nothing to plan"
    );
    // At the task until it ends (100 + 5 s).
    assert!(w.handle(WindowEvent::Tick, at(104.9, 0.3)).is_empty());
    let actions = w.handle(WindowEvent::Tick, at(105.0, 0.4));
    let end = ended(&actions);
    let outcome = end.outcome.expect("outcome");
    let r = &outcome.report;
    assert_eq!((r.task.as_str(), r.window, r.began_s), ("goal1", 0, 0.0));
    assert_eq!((r.arrival_s, r.on_time), (Some(80.0), true));
    assert!(close(r.budget_s, margin().budget(99.0)));
    assert_eq!(r.planned_information, f.scale().of(&curious_points()));
    assert_eq!(r.shortest_information, f.scale().of(&shortest_points(FROM)));
    assert_eq!(r.driven_information, f.scale().of(&[FROM, GOAL]));
    assert!(r.planned_information > r.shortest_information);
    assert_eq!((r.replans, r.peb_mean_m), (0, Some(0.1)));
    let (d, theta) = path_measure(&path);
    let predicted_s = TimeModel::table_i().eta(d, theta);
    let time_model = r.time_model.expect("time model");
    assert!(close(time_model.predicted_s, predicted_s));
    assert!(close(time_model.driving_s, 79.0));
    assert!(close(time_model.driven_share, 0.79), "79 s of 100");
    assert_eq!(outcome.plans, vec![curious_points()]);
    assert_eq!(outcome.shortest, shortest_points(FROM));
    // The margin learnt from the drive (it took far longer than predicted).
    let mut learnt = margin();
    learnt.learn(predicted_s, 79.0);
    assert_eq!(end.handover.margin, learnt);
    assert_ne!(learnt, margin());
    assert_eq!(end.handover.missions_sent, 1);
    assert_eq!(end.position, GOAL);
    // Done is done.
    assert!(w.handle(WindowEvent::Tick, at(106.0, 0.5)).is_empty());
}

#[test]
fn a_window_is_given_up_past_its_task_start() {
    let f = fixture();
    let (mut w, _) = f.driving(true);
    // Late (past the task's start): the last safe moment sends it straight...
    let straight = w.handle(WindowEvent::Tick, at(159.5, 1.0));
    assert_eq!(
        straight[0],
        WindowAction::Replanned {
            reason: Reason::LastSafeMoment
        }
    );
    // ...and 60 s after the task's start, not before, the window is given up.
    assert!(w.handle(WindowEvent::Tick, at(160.0, 1.0)).is_empty());
    let actions = w.handle(WindowEvent::Tick, at(160.5, 1.0));
    assert_eq!(actions[0], WindowAction::GaveUp);
    assert_eq!(actions.len(), 2, "no plan for the next window: {actions:?}");
    let end = ended(&actions);
    let r = end.outcome.expect("outcome").report;
    assert_eq!((r.arrival_s, r.on_time), (None, false));
    let time_model = r.time_model.expect("time model");
    assert_eq!(
        (time_model.predicted_s, time_model.driven_share),
        (0.0, 0.0)
    );
    assert_eq!(end.handover.margin, margin(), "nothing to learn from");
    assert!(end.handover.planned_ahead.is_none());
}

#[test]
fn stuck_replans_the_shortest_way_and_the_report_counts_it() {
    let f = fixture();
    let (mut w, first) = f.driving(false);
    let here = [0.1, 0.7];
    assert!(w.handle(estimate(here, 0.1, 5.0), at(5.0, 0.1)).is_empty());
    let actions = w.handle(status(&first.id, MissionState::Stuck, 8.0), at(6.0, 0.2));
    let ask = asked(&actions);
    assert_eq!((ask.from, ask.curious), (here, false));
    let actions = answer(&mut w, shortest_reply(here), at(6.0, 0.3));
    assert_eq!(
        actions[0],
        WindowAction::Replanned {
            reason: Reason::Stuck
        }
    );
    let second = sent(&actions);
    assert_eq!(second.id, "robot-tag-w0-m2");
    assert_eq!(
        second.waypoints,
        mission_waypoints(&shortest_points(here), 1.0)
    );
    // The first mission's statuses no longer count.
    let stale = status(&first.id, MissionState::Completed, 0.0);
    assert!(w.handle(stale, at(7.0, 0.4)).is_empty());
    let actions = w.handle(
        status(&second.id, MissionState::Completed, 0.0),
        at(30.0, 0.5),
    );
    let WindowAction::Arrived { drives, .. } = &actions[0] else {
        panic!("{actions:?}");
    };
    // Stuck: the replaced mission teaches nothing; nor does the arrival, with no
    // estimate since the robot was where the last mission was sent.
    assert!(drives.is_empty(), "{drives:?}");
    let r = report(&w.handle(WindowEvent::Tick, at(105.0, 0.6)));
    assert_eq!(r.replans, 1);
    assert_eq!(r.replan_reasons, vec![Reason::Stuck.name().to_owned()]);
    // The share driven counts from the first mission (1 s), the time model's from the
    // last (6 s).
    let time_model = r.time_model.expect("time model");
    assert!(close(time_model.driven_share, 0.29));
    assert!(close(time_model.driving_s, 24.0));
    assert_eq!(r.planned_information, f.scale().of(&curious_points()));
}

#[test]
fn the_first_plan_is_asked_again_until_the_window_is_given_up() {
    let f = fixture();
    let (mut w, _) = f.begin(false);
    assert!(answer(&mut w, failed(), at(1.0, 0.5)).is_empty());
    assert!(w.handle(WindowEvent::Tick, at(1.2, 1.0)).is_empty());
    let actions = w.handle(WindowEvent::Tick, at(2.0, 1.5));
    let ask = asked(&actions);
    assert!(
        close(ask.t_exec_s, margin().budget(97.0)),
        "asked anew: {ask:?}"
    );
    // Past the give-up time (60 s after the task's start) the window is given up.
    let actions = answer(&mut w, failed(), at(161.0, 2.0));
    assert_eq!(actions[0], WindowAction::GaveUp);
    let end = ended(&actions);
    let outcome = end.outcome.expect("outcome");
    let r = &outcome.report;
    assert_eq!(r.replan_reasons, vec![NO_PLAN_REASON.to_owned()]);
    assert_eq!((r.budget_s, r.time_model), (100.0, None));
    assert_eq!(outcome.driven, vec![FROM]);
    assert_eq!(end.handover.missions_sent, 0);
}

#[test]
fn a_task_over_before_its_window_is_skipped() {
    let f = fixture();
    let handover = Handover {
        missions_sent: 4,
        ..Handover::first(margin())
    };
    let (mut w, actions) = DowntimeWindow::begin(f.setup(0, FROM, true), handover, at(105.0, 0.0));
    assert_eq!(actions[0], WindowAction::Skipped);
    let end = ended(&actions);
    assert!(end.outcome.is_none());
    assert_eq!(end.handover.missions_sent, 4);
    assert!(w.handle(WindowEvent::Tick, at(106.0, 1.0)).is_empty());
}
