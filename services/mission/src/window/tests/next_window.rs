//! The next window's plan, asked at the arrival and made during the task: used when
//! the next window begins where and when it assumed, dropped when late, and asked again
//! with a growing wait after failures.

use super::*;

/// The first window driven and arrived at 80 s (wall 1 s); the actions of the arrival.
fn arrived(w: &mut DowntimeWindow<'_>, mission: &Mission) -> Vec<WindowAction> {
    w.handle(
        status(&mission.id, MissionState::Completed, 0.0),
        at(80.0, 1.0),
    )
}

/// The margin after the first window's drive (predicted by Table I, took 79 s).
fn learnt_margin() -> ArrivalMargin {
    let path: Vec<[f64; 2]> = std::iter::once(FROM).chain(curious_points()).collect();
    let (d, theta) = path_measure(&path);
    let mut m = margin();
    m.learn(TimeModel::table_i().eta(d, theta), 79.0);
    m
}

/// A next-window plan refused again and again (say its place is inside what the fleet
/// saw occupied) is asked again after 1, 2, 4, 8 and then every 8 wall seconds, not
/// every second until the task ends.
#[test]
fn the_next_windows_plan_is_asked_again_later_after_each_failure_in_a_row() {
    let f = fixture();
    let (mut w, mission) = f.driving(true);
    let mut ask = asked(&arrived(&mut w, &mission));
    let mut wall_s = 1.0;
    let mut waits = Vec::new();
    for _ in 0..6 {
        let refused = WindowEvent::PlanFailed { id: ask.id };
        assert!(w.handle(refused, at(81.0, wall_s)).is_empty());
        let refused_at = wall_s;
        ask = loop {
            wall_s += 0.25;
            assert!(wall_s < 100.0, "never asked again");
            let actions = w.handle(WindowEvent::Tick, at(81.0 + wall_s / 100.0, wall_s));
            if let Some(WindowAction::RequestPlan(next)) = actions.first() {
                break next.clone();
            }
        };
        assert_eq!((ask.from, ask.to), (GOAL, NEXT));
        waits.push(wall_s - refused_at);
    }
    assert_eq!(waits, vec![1.0, 2.0, 4.0, 8.0, 8.0, 8.0]);
    // An answer at last is the next window's plan.
    let next_route = line(GOAL, NEXT);
    let reply = WindowEvent::PlanReply {
        id: ask.id,
        plan: Box::new(Plan {
            shortest: attached(next_route.clone()),
            ..plan(PlannerModel::Model1, next_route, 50.0)
        }),
    };
    assert!(w.handle(reply, at(90.0, wall_s)).is_empty());
    let end = ended(&w.handle(WindowEvent::Tick, at(105.0, wall_s + 1.0)));
    assert!(end.handover.planned_ahead.is_some());
}

#[test]
fn the_wait_before_asking_again_doubles_from_plan_retry_s_to_max_plan_retry_s() {
    let waits: Vec<f64> = (1..=7).map(plan_retry_after_s).collect();
    assert_eq!(waits, vec![1.0, 2.0, 4.0, 8.0, 8.0, 8.0, 8.0]);
    assert_eq!(plan_retry_after_s(0), PLAN_RETRY_S);
    assert_eq!(plan_retry_after_s(u32::MAX), MAX_PLAN_RETRY_S);
}

#[test]
fn the_next_window_is_planned_during_the_task() {
    let f = fixture();
    let (mut w, mission) = f.driving(true);
    let actions = arrived(&mut w, &mission);
    assert!(matches!(actions[0], WindowAction::Arrived { .. }));
    // From the task's place, for the time from the task's end (105 s) to the next
    // task (200 s), with the margin the drive just taught.
    let ask = asked(&actions);
    assert_eq!((ask.from, ask.to, ask.curious), (GOAL, NEXT, true));
    let budget_s = learnt_margin().budget(95.0);
    assert!(close(ask.t_exec_s, budget_s), "{ask:?} {budget_s}");
    let next_route = line(GOAL, NEXT);
    let reply = reply(Plan {
        shortest: attached(next_route.clone()),
        ..plan(PlannerModel::Model1, next_route.clone(), 50.0)
    });
    assert!(
        answer(&mut w, reply, at(81.0, 1.5)).is_empty(),
        "at the task still"
    );
    let end = ended(&w.handle(WindowEvent::Tick, at(105.0, 2.0)));
    let ahead = end.handover.planned_ahead.clone().expect("planned ahead");
    assert_eq!((ahead.window, ahead.from), (1, GOAL));
    assert!(close(ahead.budget_s, budget_s));

    // The next window starts on it at once when the robot is where it starts...
    let near = [3.2, 0.2];
    let (_, actions) = DowntimeWindow::begin(
        f.setup(1, near, false),
        end.handover.clone(),
        at(105.0, 0.0),
    );
    assert_eq!(
        actions[0],
        WindowAction::Planned {
            budget_s,
            eta_s: 50.0,
            curious: true,
            late_probability: learnt_margin().late_probability(50.0, 95.0),
        }
    );
    let mission = sent(&actions);
    assert_eq!(mission.id, "robot-tag-w1-m2", "ids go on counting");
    assert_eq!(mission.waypoints, mission_waypoints(&next_route, 1.0));
    // ...and asks again when it is not (0.9 m away).
    let far = [3.1, 1.0];
    let (_, actions) = DowntimeWindow::begin(f.setup(1, far, false), end.handover, at(105.0, 0.0));
    assert_eq!(asked(&actions).from, far);
}

#[test]
fn a_plan_for_the_next_window_after_the_task_ended_is_dropped() {
    let f = fixture();
    let (mut w, mission) = f.driving(true);
    arrived(&mut w, &mission);
    // No planner answered: asked again a second later (wall), while the task lasts.
    assert!(answer(&mut w, failed(), at(81.0, 2.0)).is_empty());
    assert!(w.handle(WindowEvent::Tick, at(82.0, 2.5)).is_empty());
    let actions = w.handle(WindowEvent::Tick, at(83.0, 3.0));
    assert_eq!(asked(&actions).from, GOAL);
    // The answer comes after the task ended: the window is done without it.
    let late = reply(Plan {
        shortest: attached(line(GOAL, NEXT)),
        ..plan(PlannerModel::Model1, line(GOAL, NEXT), 50.0)
    });
    let end = ended(&answer(&mut w, late, at(106.0, 4.0)));
    assert!(end.handover.planned_ahead.is_none());
}
