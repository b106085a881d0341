//! The rules that keep the robot on time and free: the last safe moment, a PEB hold
//! recovered, and the next window planned while driving beside a replan.

use super::*;

#[test]
fn at_the_last_safe_moment_the_robot_goes_straight_and_stays_straight() {
    let f = fixture();
    let (mut w, first) = f.driving(false);
    // On its curious route at 95 s, 5 s before the task: the fastest path from here
    // takes longer than what the margin leaves of 5 s.
    let here = [0.1, 1.1];
    let actions = w.handle(estimate(here, 0.1, 95.0), at(95.0, 0.5));
    assert_eq!(
        actions[0],
        WindowAction::Replanned {
            reason: Reason::LastSafeMoment
        }
    );
    let straight = sent(&actions);
    assert_ne!(straight.id, first.id);
    assert_eq!(straight.waypoints.last().copied(), Some(GOAL));
    assert!(
        !actions
            .iter()
            .any(|a| matches!(a, WindowAction::RequestPlan(_))),
        "no planner"
    );
    // Curious no more: far early on the new route is not slack.
    let again = w.handle(
        status(&straight.id, MissionState::Active, 0.5),
        at(97.0, 0.6),
    );
    assert!(again.is_empty(), "{again:?}");
    let r = report(&{
        w.handle(
            status(&straight.id, MissionState::Completed, 0.0),
            at(99.0, 0.7),
        );
        w.handle(WindowEvent::Tick, at(105.0, 0.8))
    });
    assert!(r.on_time);
    assert_eq!(
        r.replan_reasons,
        vec![Reason::LastSafeMoment.name().to_owned()]
    );
}

#[test]
fn the_last_safe_moment_leaves_room_for_a_check_away_and_back() {
    let f = fixture();
    let here = [0.1, 1.1];
    let fastest = straight::fastest_route(&f.scale(), TimeModel::table_i(), here, GOAL)
        .expect("a fastest path")
        .t_eta_s;
    // The margin's budget of the time left less two check periods (the robot may drive
    // one away from the task before the next check, and one back) meets the fastest
    // path's time between these two moments.
    let fires = |t: f64| {
        let (mut w, _) = f.driving(false);
        let actions = w.handle(estimate(here, 0.1, t), at(t, 0.5));
        actions.first()
            == Some(&WindowAction::Replanned {
                reason: Reason::LastSafeMoment,
            })
    };
    let start = 100.0;
    let latest = (0..400)
        .map(|i| start - 20.0 + 0.05 * f64::from(i))
        .find(|&t| fires(t))
        .expect("fires before the task");
    let time_left = start - latest;
    assert!(
        margin().budget(time_left - 2.0 * SAFE_CHECK_S) <= fastest + 1e-9,
        "fired at {time_left} s left"
    );
    assert!(
        margin().budget(time_left + 0.05 - 2.0 * SAFE_CHECK_S) > fastest,
        "fired late: {time_left} s left, fastest {fastest} s"
    );
    // With one check period only, it would have waited longer than it may.
    assert!(margin().budget(time_left - SAFE_CHECK_S) > fastest);
}

#[test]
fn a_robot_held_for_its_peb_is_driven_back_to_its_last_fix_then_replanned() {
    let f = fixture();
    let (mut w, first) = f.driving(false);
    for (p, peb) in [
        ([0.1, 0.3], 0.3),
        ([0.1, 0.5], 0.4),
        ([0.1, 0.7], 3.0),
        ([0.1, 0.9], 9.0),
    ] {
        assert!(w.handle(estimate(p, peb, 5.0), at(5.0, 0.1)).is_empty());
    }
    let held = |w: &mut DowntimeWindow<'_>, t: f64| {
        w.handle(status(&first.id, MissionState::HaltedPeb, 2.0), at(t, 0.2))
    };
    assert!(held(&mut w, 10.0).is_empty());
    assert!(held(&mut w, 13.9).is_empty(), "within its patience");
    let actions = held(&mut w, 14.1);
    assert!(matches!(actions[0], WindowAction::Recovering { held_s } if close(held_s, 4.1)));
    let back = sent(&actions);
    assert!(back.recovery, "the guard lets a recovery through");
    // Back past the last fix ([0.1, 0.5]) by RECOVERY_BACK_M, here to the track's start.
    assert_eq!(back.waypoints.last().copied(), Some(FROM), "{back:?}");
    // Back at the fix: straight to the task from there, without the planner.
    let actions = answer_status(&mut w, &back, MissionState::Completed, at(20.0, 0.3));
    assert!(!actions
        .iter()
        .any(|a| matches!(a, WindowAction::RequestPlan(_))));
    assert_eq!(
        actions[0],
        WindowAction::Replanned {
            reason: Reason::Recovered
        }
    );
    let onward = sent(&actions);
    assert!(!onward.recovery);
    answer_status(&mut w, &onward, MissionState::Completed, at(70.0, 0.5));
    let r = report(&w.handle(WindowEvent::Tick, at(105.0, 0.6)));
    assert_eq!((r.holds, r.recoveries), (1, 1));
    assert!(close(r.held_s, 4.1), "{r:?}");
    assert!(r.on_time);
}

#[test]
fn with_plan_ahead_the_next_window_is_asked_while_driving_beside_a_replan() {
    let f = fixture();
    let mut setup = f.setup(0, FROM, true);
    setup.rules.plan_ahead = true;
    let (mut w, actions) = DowntimeWindow::begin(setup, Handover::first(margin()), at(0.0, 0.0));
    let first_id = asked(&actions).id;
    let actions = w.handle(
        WindowEvent::PlanReply {
            id: first_id,
            plan: Box::new(Plan {
                shortest: attached(shortest_points(FROM)),
                ..plan(PlannerModel::Model1, curious_points(), CURIOUS_ETA_S)
            }),
        },
        at(1.0, 0.0),
    );
    let mission = sent(&actions);
    let ahead = asked(&actions);
    assert_eq!(
        (ahead.from, ahead.to),
        (GOAL, NEXT),
        "the next window, from this task"
    );
    // A replan while the next window's plan is made: two in flight.
    let pushed = [2.0, 2.5];
    let replan = asked(&w.handle(estimate(pushed, 0.1, 3.0), at(3.0, 0.1)));
    assert_ne!(replan.id, ahead.id);
    assert_eq!(w.asks_in_flight(), 2);
    let next_route = line(GOAL, NEXT);
    let ahead_reply = WindowEvent::PlanReply {
        id: ahead.id,
        plan: Box::new(Plan {
            shortest: attached(next_route.clone()),
            ..plan(PlannerModel::Model1, next_route, 50.0)
        }),
    };
    assert!(w.handle(ahead_reply, at(3.5, 0.2)).is_empty());
    // Arriving forgets the replan; nothing more is asked at the task.
    let actions = w.handle(
        status(&mission.id, MissionState::Completed, 0.0),
        at(60.0, 0.3),
    );
    assert_eq!(actions[0], WindowAction::Forget(replan.id));
    assert!(!actions
        .iter()
        .any(|a| matches!(a, WindowAction::RequestPlan(_))));
    // Its late answer changes nothing.
    let late = WindowEvent::PlanFailed { id: replan.id };
    assert!(w.handle(late, at(61.0, 0.4)).is_empty());
    let end = ended(&w.handle(WindowEvent::Tick, at(105.0, 0.5)));
    let planned = end.handover.planned_ahead.expect("planned while driving");
    assert_eq!((planned.window, planned.leave_at_s), (1, 105.0));
    // A window that begins well after the plan assumed takes a fresh one.
    let handover = Handover {
        planned_ahead: Some(planned),
        ..end.handover
    };
    let (_, actions) = DowntimeWindow::begin(f.setup(1, GOAL, false), handover, at(110.0, 0.0));
    assert!(
        matches!(actions[0], WindowAction::RequestPlan(_)),
        "{actions:?}"
    );
}

/// A robot still held when its window ended: the next window has no fix on its own
/// track (it begins where the robot is held) and drives it back along the previous
/// window's track to that window's last fix, instead of holding it there for good.
#[test]
fn a_robot_held_across_windows_is_driven_back_along_the_previous_track() {
    let f = fixture();
    // The previous window: a fix at [-2.1, 0.1], then into the gap to FROM.
    let track = vec![[-3.1, 0.1], [-2.1, 0.1], [-1.1, 0.1], FROM];
    let handover = Handover {
        track: track.clone(),
        fix: 1,
        ..Handover::first(margin())
    };
    let (mut w, _) = DowntimeWindow::begin(f.setup(0, FROM, false), handover, at(0.0, 0.0));
    let first = sent(&answer(&mut w, curious_reply(true), at(1.0, 0.0)));
    // Held at once, its estimates without a fix.
    assert!(w.handle(estimate(FROM, 9.0, 2.0), at(2.0, 0.1)).is_empty());
    let held = |w: &mut DowntimeWindow<'_>, t: f64| {
        w.handle(status(&first.id, MissionState::HaltedPeb, 2.0), at(t, 0.2))
    };
    assert!(held(&mut w, 3.0).is_empty());
    let actions = held(&mut w, 8.0);
    assert!(
        matches!(actions[0], WindowAction::Recovering { .. }),
        "{actions:?}"
    );
    let back = sent(&actions);
    assert!(back.recovery);
    // Back to the previous window's fix ([-2.1, 0.1], more than RECOVERY_BACK_M back).
    assert_eq!(back.waypoints.last().copied(), Some(track[1]), "{back:?}");
    // The window's own track (its report) does not hold the previous one's.
    let onward = sent(&answer_status(
        &mut w,
        &back,
        MissionState::Completed,
        at(20.0, 0.3),
    ));
    answer_status(&mut w, &onward, MissionState::Completed, at(70.0, 0.5));
    let end = w.handle(WindowEvent::Tick, at(105.0, 0.6));
    let outcome = end
        .iter()
        .find_map(|a| match a {
            WindowAction::Done(end) => end.outcome.clone(),
            _ => None,
        })
        .expect("the window's outcome");
    assert_eq!(outcome.driven.first().copied(), Some(FROM));
}

#[test]
fn a_held_robot_whose_controller_reports_is_not_called_silent() {
    // The controller reports HaltedPeb on every update; the window waits out its
    // patience and recovers, but never replans for a silent controller (3 s here), which
    // would resend a mission the controller is answering, every 3 s, for as long as the
    // robot is held.
    let f = fixture();
    let (mut w, first) = f.driving(false);
    let mut actions = Vec::new();
    for k in 0..20 {
        let t = 10.0 + 0.2 * f64::from(k);
        actions.extend(w.handle(status(&first.id, MissionState::HaltedPeb, 2.0), at(t, t)));
        actions.extend(w.handle(WindowEvent::Tick, at(t + 0.1, t + 0.1)));
    }
    // A silent-controller replan asks the planner first (a curious window): no ask, no
    // replan.
    assert!(
        !actions.iter().any(|a| matches!(
            a,
            WindowAction::RequestPlan(_) | WindowAction::Replanned { .. }
        )),
        "{actions:?}"
    );
    // Held for 3.8 s of the 4 s patience: no recovery yet either.
    assert!(!actions
        .iter()
        .any(|a| matches!(a, WindowAction::Recovering { .. })));
    // A controller that says nothing at all is still called silent: the replan's ask.
    let quiet = w.handle(WindowEvent::Tick, at(20.0, 20.0));
    assert!(
        quiet
            .iter()
            .any(|a| matches!(a, WindowAction::RequestPlan(_))),
        "{quiet:?}"
    );
}

/// The last safe moment is checked once in each second of the mission clock (counted
/// from 0, not from the last check), at the robot's last estimate: near the task at
/// 94.6 s it is safe; a tick at 95.1 s, the estimate still from 94.6 s, checks nothing
/// new; the robot seen far back on its route at 95.2 s is checked (a new second, though
/// less than a second after the last check), and it goes straight.
#[test]
fn the_last_safe_moment_is_checked_once_a_second_at_the_last_estimate() {
    let f = fixture();
    let (mut w, _) = f.driving(false);
    let near = [3.1, 0.3];
    assert!(w
        .handle(estimate(near, 0.1, 94.6), at(94.6, 0.5))
        .is_empty());
    assert!(w.handle(WindowEvent::Tick, at(95.1, 0.5)).is_empty());
    let far = [0.1, 1.1];
    let actions = w.handle(estimate(far, 0.1, 95.2), at(95.2, 0.5));
    assert_eq!(
        actions.first(),
        Some(&WindowAction::Replanned {
            reason: Reason::LastSafeMoment
        }),
        "{actions:?}"
    );
}

/// The straight route sent at the last safe moment starts where the moving robot was:
/// its drive is not timed (the robot drove on along its old route while the mission
/// travelled), so the arrival teaches the calibration nothing.
#[test]
fn a_straight_route_from_a_moving_robot_does_not_teach_the_time_model() {
    let f = fixture();
    let (mut w, _) = f.driving(false);
    let actions = w.handle(estimate([0.1, 1.1], 0.1, 95.0), at(95.0, 0.5));
    let straight = sent(&actions);
    w.handle(estimate(GOAL, 0.1, 98.5), at(98.5, 0.6));
    let actions = w.handle(
        status(&straight.id, MissionState::Completed, 0.0),
        at(99.0, 0.7),
    );
    let WindowAction::Arrived { drives, .. } = &actions[0] else {
        panic!("{actions:?}");
    };
    assert!(
        drives.iter().all(|d| d.path.last() != Some(&GOAL)),
        "{drives:?}"
    );
}
