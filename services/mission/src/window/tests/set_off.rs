//! The window's time is not spent waiting: the robot sets off on the fastest path while
//! its curious plan is made, and the slack rule measures what a replan would add.

use super::*;

fn setting_off(f: &Fixture) -> (DowntimeWindow<'_>, Vec<WindowAction>) {
    let mut setup = f.setup(0, FROM, false);
    setup.rules.set_off_at_once = true;
    DowntimeWindow::begin(setup, Handover::first(margin()), at(0.0, 0.0))
}

#[test]
fn without_a_plan_made_ahead_the_robot_sets_off_while_the_curious_plan_is_made() {
    let f = fixture();
    let (mut w, actions) = setting_off(&f);
    // At once: the window's own fastest path, sent, then the curious plan asked.
    assert!(matches!(
        actions[0],
        WindowAction::Planned { curious: false, .. }
    ));
    let first = sent(&actions);
    assert_eq!(first.id, "robot-tag-w0-m1");
    assert_eq!(first.waypoints.last().copied(), Some(GOAL));
    let ask = asked(&actions);
    assert!(ask.curious);
    // From where the robot will be when the plan comes: 1 s (the plan's cost) at the
    // model's 0.5 m/s along the way east, 0.5 m.
    assert!(distance(ask.from, [0.6, 0.1]) < 1e-9, "{ask:?}");
    assert!(close(ask.t_exec_s, margin().budget(99.0)), "{ask:?}");
    // The plan comes: the robot takes it from there, and the report calls it the
    // window's plan.
    let actions = answer(&mut w, curious_reply(true), at(1.0, 0.0));
    assert_eq!(
        actions[0],
        WindowAction::Replanned {
            reason: Reason::SetOff
        }
    );
    let curious = sent(&actions);
    assert_eq!(curious.id, "robot-tag-w0-m2");
    let arrived = answer_status(&mut w, &curious, MissionState::Completed, at(60.0, 1.0));
    let ended = w.handle(WindowEvent::Tick, at(106.0, 2.0));
    let report = report(&[arrived, ended].concat());
    assert_eq!(report.replan_reasons, vec![Reason::SetOff.name()]);
    assert!(report.planned_information > 0.0);
    assert!(close(report.budget_s, margin().budget(99.0)));
}

#[test]
fn a_set_off_plan_that_fails_leaves_the_robot_on_the_fastest_path() {
    let f = fixture();
    let (mut w, actions) = setting_off(&f);
    let first = sent(&actions);
    assert!(answer(&mut w, failed(), at(1.0, 0.0)).is_empty());
    assert_eq!(w.asks_in_flight(), 0);
    let arrived = answer_status(&mut w, &first, MissionState::Completed, at(20.0, 1.0));
    assert!(arrived
        .iter()
        .any(|a| matches!(a, WindowAction::Arrived { .. })));
}

#[test]
fn no_slack_when_a_replan_would_only_keep_the_earliness_back_as_its_margin() {
    let f = fixture();
    // A margin that keeps back a quarter of the time left after 2 s.
    let wide = || {
        let mut m = ArrivalMargin::new(0.25, 2.0, 1.0);
        m.learn(10.0, 10.0);
        m
    };
    let mut setup = f.setup(0, FROM, false);
    setup.watch.slack_s = 3.0;
    let (mut w, _) = DowntimeWindow::begin(setup, Handover::first(wide()), at(60.0, 0.0));
    let first = sent(&answer(&mut w, curious_reply(true), at(61.0, 0.0)));
    assert!(w
        .handle(estimate([0.1, 0.9], 0.1, 80.0), at(80.0, 0.1))
        .is_empty());
    // At 80 s, 6 m left at 0.5 m/s: 12 s of drive, 8 s early. A replan asked now would
    // get (20 − 1 − 2) / 1.25 = 13.6 s: 1.6 s more than the drive, under slack_s.
    let quiet = w.handle(status(&first.id, MissionState::Active, 6.0), at(80.0, 0.2));
    assert!(quiet.is_empty(), "{quiet:?}");
    // With 4 m left (8 s of drive) the same budget is 5.6 s more: slack.
    let w2 = w.handle(status(&first.id, MissionState::Active, 4.0), at(80.5, 0.3));
    assert!(asked(&w2).curious, "{w2:?}");
}

#[test]
fn the_window_asks_its_own_curious_plan_before_the_next_windows() {
    let f = fixture();
    let mut setup = f.setup(0, FROM, true);
    setup.rules.set_off_at_once = true;
    setup.rules.plan_ahead = true;
    let (_, actions) = DowntimeWindow::begin(setup, Handover::first(margin()), at(0.0, 0.0));
    let asks: Vec<&PlanAsk> = actions
        .iter()
        .filter_map(|a| match a {
            WindowAction::RequestPlan(ask) => Some(ask),
            _ => None,
        })
        .collect();
    assert_eq!(asks.len(), 2, "{actions:?}");
    // The planner answers a client's requests in order: this window's first, from the
    // way to GOAL; then the next window's, from GOAL.
    assert!(distance(asks[0].from, [0.6, 0.1]) < 1e-9, "{:?}", asks[0]);
    assert_eq!(asks[1].from, GOAL);
}
