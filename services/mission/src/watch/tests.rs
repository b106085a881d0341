//! The replan policy's rules, one event at a time.

use super::*;

fn params() -> WatchParams {
    WatchParams {
        off_path_m: 1.5,
        speed_m_per_s: 0.5,
        expected_speed_m_per_s: 0.5,
        max_replans: 3,
        give_up_after_s: 60.0,
        controller_silence_s: 3.0,
        slack_s: 10.0,
        slack_interval_s: 5.0,
        min_replan_window_s: 0.0,
        behind: true,
    }
}

fn watch() -> Watch {
    // A task at 100 s, the path straight along x from 0 to 20 m, planned at 0 s.
    Watch::new(params(), 100.0, vec![[0.0, 0.0], [20.0, 0.0]], 0.0, 0.0)
}

#[test]
fn completed_is_an_arrival() {
    let mut w = watch();
    assert_eq!(
        w.on_status(Status::Completed, 42.0, 1.0, 1.0),
        Decision::Arrived { at_s: 42.0 }
    );
}

#[test]
fn slack_fires_when_early_and_not_too_often() {
    let mut w = watch();
    // 10 m left at 0.5 m/s = 20 s: at 6 s a replan would get 80 s of budget.
    let d = w.on_status(
        Status::Active {
            distance_left_m: 10.0,
        },
        6.0,
        1.0,
        80.0,
    );
    assert_eq!(
        d,
        Decision::Replan {
            reason: Reason::Slack,
            curious: true,
            resend: false
        }
    );
    w.replanned(vec![[0.0, 0.0], [20.0, 0.0]], Replanned::Curious, 6.0, 1.0);
    // Right after the replan: not again before slack_interval_s.
    assert_eq!(
        w.on_status(
            Status::Active {
                distance_left_m: 10.0
            },
            8.0,
            1.5,
            80.0
        ),
        Decision::Keep
    );
    // Arriving 20 s early, but a plan asked now would keep most of it back as its
    // margin and cost (a budget of 28 s for 20 s of drive, under slack_s more):
    // nothing.
    assert_eq!(
        w.on_status(
            Status::Active {
                distance_left_m: 10.0
            },
            60.0,
            1.8,
            28.0
        ),
        Decision::Keep
    );
    // A budget 10.5 s longer than the drive: slack.
    assert!(matches!(
        w.on_status(
            Status::Active {
                distance_left_m: 10.0
            },
            62.0,
            2.0,
            30.5
        ),
        Decision::Replan {
            reason: Reason::Slack,
            ..
        }
    ));
}

#[test]
fn slack_is_predicted_from_the_robots_own_progress() {
    // The model expects 0.1 m/s (arrival far too late to be early), but the robot
    // covers 1 m/s along the path: the slack rule sees it once it has driven a bit.
    let mut w = Watch::new(
        WatchParams {
            expected_speed_m_per_s: 0.1,
            ..params()
        },
        100.0,
        vec![[0.0, 0.0], [40.0, 0.0]],
        0.0,
        0.0,
    );
    let active = |left| Status::Active {
        distance_left_m: left,
    };
    // A replan's budget: the time left less 10%.
    let budget = |now_s: f64| (100.0 - now_s) * 0.9;
    assert_eq!(
        w.on_status(active(40.0), 11.0, 0.1, budget(11.0)),
        Decision::Keep
    );
    assert_eq!(
        w.on_status(active(38.0), 13.0, 0.2, budget(13.0)),
        Decision::Keep,
        "too soon to tell"
    );
    assert!(matches!(
        w.on_status(active(35.0), 16.0, 0.3, budget(16.0)),
        Decision::Replan {
            reason: Reason::Slack,
            ..
        }
    ));
}

#[test]
fn behind_the_plan_replans_curious_with_the_time_left() {
    // 20 m left at the configured 0.5 m/s would arrive at 70 s for a task at 100 s,
    // but the robot makes 0.25 m/s along the path (turns, a crowd): at that pace it
    // arrives at 110 s. Not late, behind: a curious plan that fits the time left.
    // (The time model expects 0.3 m/s: no slack before the robot's pace is known.)
    let params = WatchParams {
        expected_speed_m_per_s: 0.3,
        ..params()
    };
    let mut w = Watch::new(params, 100.0, vec![[0.0, 0.0], [40.0, 0.0]], 0.0, 0.0);
    let active = |left| Status::Active {
        distance_left_m: left,
    };
    assert_eq!(w.on_status(active(21.0), 26.0, 0.1, 1.0), Decision::Keep);
    let behind = Decision::Replan {
        reason: Reason::Behind,
        curious: true,
        resend: false,
    };
    assert_eq!(w.on_status(active(20.0), 30.0, 0.2, 1.0), behind);
    w.replanned(
        vec![[20.0, 0.0], [40.0, 0.0]],
        Replanned::Curious,
        30.0,
        0.2,
    );
    // Not again before slack_interval_s, and not on a pace that arrives in time.
    assert_eq!(w.on_status(active(19.0), 31.0, 0.3, 1.0), Decision::Keep);
    assert_eq!(w.on_status(active(18.0), 34.0, 0.4, 1.0), Decision::Keep);
    // 0.3 m/s since the replan arrives at 94 s: in time, and not early enough to be slack.
    assert_eq!(w.on_status(active(17.5), 36.0, 0.5, 1.0), Decision::Keep);
    // Behind again later (0.23 m/s: 114 s): replanned again.
    assert_eq!(w.on_status(active(17.4), 38.0, 0.6, 1.0), behind);
}

#[test]
fn late_replans_the_shortest_way_once_and_never_curious_again() {
    let mut w = watch();
    let d = w.on_status(
        Status::Active {
            distance_left_m: 20.0,
        },
        70.0,
        1.0,
        1.0,
    );
    assert_eq!(
        d,
        Decision::Replan {
            reason: Reason::EtaSlipped,
            curious: false,
            resend: false
        }
    );
    w.replanned(
        vec![[10.0, 0.0], [20.0, 0.0]],
        Replanned::Curious,
        70.0,
        1.0,
    );
    // After slipping, slack never fires, and a push replans the shortest way.
    assert_eq!(
        w.on_status(
            Status::Active {
                distance_left_m: 1.0
            },
            80.0,
            2.0,
            1.0
        ),
        Decision::Keep
    );
    assert_eq!(
        w.on_estimate([10.0, 5.0]),
        Decision::Replan {
            reason: Reason::PushedOffPath,
            curious: false,
            resend: false
        }
    );
}

#[test]
fn a_stuck_robot_is_replanned_after_the_curious_replans_are_spent() {
    let mut w = watch();
    for _ in 0..params().max_replans {
        w.replanned(vec![[0.0, 0.0], [20.0, 0.0]], Replanned::Curious, 1.0, 0.0);
    }
    assert_eq!(
        w.on_estimate([0.0, 9.0]),
        Decision::Keep,
        "no curious replan left"
    );
    // Blocked: the shortest way, from a budget of its own, until that is spent too.
    for _ in 0..params().max_replans {
        assert_eq!(
            w.on_status(Status::Stuck, 2.0, 0.5, 10.0),
            Decision::Replan {
                reason: Reason::Stuck,
                curious: false,
                resend: false
            }
        );
        w.replanned(vec![[0.0, 0.0], [20.0, 0.0]], Replanned::Shortest, 2.0, 0.5);
    }
    assert_eq!(w.on_status(Status::Stuck, 3.0, 0.6, 10.0), Decision::Keep);
    assert_eq!(
        (w.replans(), w.shortest_replans()),
        (params().max_replans, params().max_replans)
    );
    // Then the way is tried again, uncounted, once per slack interval.
    let later = 2.0 + params().slack_interval_s;
    let retry = Decision::Replan {
        reason: Reason::Stuck,
        curious: false,
        resend: true,
    };
    assert_eq!(w.on_status(Status::Stuck, later, 0.7, 10.0), retry);
    w.replanned(vec![[0.0, 0.0], [20.0, 0.0]], Replanned::Resend, later, 0.7);
    assert_eq!(
        w.on_status(Status::Stuck, later + 1.0, 0.8, 10.0),
        Decision::Keep
    );
    let again = later + params().slack_interval_s;
    assert_eq!(w.on_status(Status::Stuck, again, 0.9, 10.0), retry);
}

#[test]
fn a_silent_controller_gets_the_mission_again_beyond_the_replan_limit() {
    let mut w = watch();
    for _ in 0..params().max_replans {
        w.replanned(vec![[0.0, 0.0], [20.0, 0.0]], Replanned::Curious, 1.0, 0.0);
    }
    assert_eq!(
        w.on_estimate([0.0, 9.0]),
        Decision::Keep,
        "replans are used up"
    );
    assert_eq!(
        w.on_tick(2.0, 3.5),
        Decision::Replan {
            reason: Reason::ControllerSilent,
            curious: true,
            resend: true
        }
    );
    w.replanned(vec![[0.0, 0.0], [20.0, 0.0]], Replanned::Resend, 2.0, 3.5);
    assert_eq!((w.replans(), w.resends()), (3, 1));
}

#[test]
fn a_window_is_given_up_after_its_grace() {
    let mut w = watch();
    assert_eq!(w.on_tick(159.0, 1.0), Decision::Keep);
    assert_eq!(w.on_tick(161.0, 1.0), Decision::GiveUp);
}
