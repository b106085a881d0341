//! The map changed under the route: a set of believed obstacles on the route ahead is
//! a replan round it at once, seeded with the route left; one beside the route, or one
//! heard while a plan is in flight, is not (the latter is checked when the plan is in).

use std::sync::Arc;

use super::*;

/// A pallet believed at `at`, cleared by 0.4 m.
fn obstacle_at(at: [f64; 2]) -> WindowEvent {
    WindowEvent::MapChanged(Arc::new(SeenObstacles {
        points: vec![at],
        clearance_m: 0.4,
    }))
}

/// The robot 0.2 m up the curious route's first leg at 2 s.
fn on_first_leg(w: &mut DowntimeWindow<'_>) {
    assert!(w
        .handle(estimate([0.1, 0.3], 0.1, 2.0), at(2.0, 0.1))
        .is_empty());
}

#[test]
fn an_obstacle_on_the_route_ahead_replans_round_it_seeded_with_the_route_left() {
    let f = fixture();
    let (mut w, _) = f.driving(false);
    on_first_leg(&mut w);
    // On the east leg (y = 1.1), ahead of the robot.
    let actions = w.handle(obstacle_at([2.0, 1.1]), at(2.5, 0.2));
    let ask = asked(&actions);
    assert!(ask.curious, "{ask:?}");
    // From where the robot will be when the plan comes (1 s at 0.5 m/s ahead), seeded
    // with the route left from there, through the block (the planner repairs it).
    assert!(distance(ask.from, [0.1, 0.8]) < 1e-9, "{ask:?}");
    assert_eq!(ask.seed_route.first(), Some(&ask.from));
    assert!(ask.seed_route.contains(&[2.1, 1.1]), "{ask:?}");
    // The robot drives on meanwhile; the reply is sent for the map change.
    assert!(!actions.iter().any(|a| matches!(a, WindowAction::Drive(_))));
    let actions = answer(&mut w, curious_reply(true), at(3.0, 0.3));
    assert_eq!(
        actions[0],
        WindowAction::Replanned {
            reason: Reason::MapChanged
        }
    );
    let arrived = answer_status(
        &mut w,
        &sent(&actions),
        MissionState::Completed,
        at(60.0, 1.0),
    );
    let ended = w.handle(WindowEvent::Tick, at(106.0, 2.0));
    let report = report(&[arrived, ended].concat());
    assert_eq!(report.replan_reasons, vec![Reason::MapChanged.name()]);
}

#[test]
fn an_obstacle_beside_the_route_or_behind_the_robot_changes_nothing() {
    let f = fixture();
    let (mut w, _) = f.driving(false);
    on_first_leg(&mut w);
    assert!(w.handle(obstacle_at([2.0, 2.0]), at(2.5, 0.2)).is_empty());
    // Where the robot has been (its start), not on the route left.
    assert!(w.handle(obstacle_at([0.1, -0.3]), at(2.6, 0.2)).is_empty());
    // A tick does not check the same set again.
    assert!(w.handle(WindowEvent::Tick, at(2.7, 0.3)).is_empty());
}

#[test]
fn an_obstacle_heard_while_a_plan_is_in_flight_is_checked_when_it_is_in() {
    let f = fixture();
    let (mut w, _) = f.begin(false);
    // Waiting for the first plan: nothing to check yet.
    assert!(w.handle(obstacle_at([2.0, 1.1]), at(0.5, 0.0)).is_empty());
    // The plan the planner made on its older map crosses it: the window's first tick
    // with no plan in flight finds it.
    let actions = answer(&mut w, curious_reply(true), at(1.0, 0.0));
    assert!(
        matches!(actions[0], WindowAction::Planned { .. }),
        "{actions:?}"
    );
    // Not checked at begin: the set was heard before there was a route. The window
    // checks routes against sets heard, so a route the planner sent after the set is
    // taken as planned round it.
    assert!(w.handle(WindowEvent::Tick, at(1.1, 0.1)).is_empty());
    // A new set while the robot drives is checked at once.
    let actions = w.handle(obstacle_at([2.0, 1.1]), at(1.2, 0.1));
    assert!(asked(&actions).curious, "{actions:?}");
    // A second set while that replan is in flight waits for it, then is checked.
    assert!(w.handle(obstacle_at([3.1, 0.6]), at(1.3, 0.1)).is_empty());
    let actions = answer(&mut w, curious_reply(true), at(2.0, 0.2));
    assert_eq!(
        actions[0],
        WindowAction::Replanned {
            reason: Reason::MapChanged
        }
    );
    // The new route (the curious route again) passes (3.1, 0.6): the next tick replans.
    let actions = w.handle(WindowEvent::Tick, at(2.1, 0.3));
    assert!(asked(&actions).curious, "{actions:?}");
}

#[test]
fn a_straight_route_blocked_asks_the_planner_for_the_shortest_way() {
    let f = fixture();
    let (mut w, _) = f.driving(false);
    on_first_leg(&mut w);
    // The robot sent straight (the last safe moment): curious no more.
    let actions = w.handle(estimate([0.1, 0.3], 0.1, 96.0), at(96.0, 1.0));
    assert!(
        actions.contains(&WindowAction::Replanned {
            reason: Reason::LastSafeMoment
        }),
        "{actions:?}"
    );
    let straight = sent(&actions);
    let on_it = straight.waypoints[straight.waypoints.len() / 2];
    let actions = w.handle(obstacle_at(on_it), at(96.2, 1.1));
    let ask = asked(&actions);
    assert!(!ask.curious && ask.seed_route.is_empty(), "{ask:?}");
}

#[test]
fn the_windows_own_fastest_path_goes_round_what_the_fleet_has_seen() {
    let f = fixture();
    let (mut w, _) = f.driving(false);
    on_first_leg(&mut w);
    let near = |route: &Route, p: [f64; 2]| {
        route
            .points
            .iter()
            .map(|&q| distance(q, p))
            .fold(f64::INFINITY, f64::min)
    };
    let pallet = [1.7, 0.3];
    let before = w.fastest_from_here().expect("a fastest path");
    assert!(near(&before, pallet) < 0.3, "{before:?}");
    // Beside the curious route (y = 1.1): no replan, but the straight way is blocked.
    assert!(w.handle(obstacle_at(pallet), at(2.5, 0.2)).is_empty());
    let round = w.fastest_from_here().expect("a way round");
    assert!(near(&round, pallet) > 0.4, "{round:?}");
    assert!(round.t_eta_s > before.t_eta_s);
    // With the robot inside the clearance, the static map's way is taken.
    assert!(w
        .handle(estimate([1.7, 0.5], 0.1, 3.0), at(3.0, 0.3))
        .iter()
        .all(|a| !matches!(a, WindowAction::Drive(_))));
    assert!(w.fastest_from_here().is_some());
}
