//! A restarted executive's first window and its predecessor's route (`resume.rs`).

use super::*;

fn resumed(task: &str, start_s: f64) -> Resumed {
    Resumed {
        task: task.into(),
        task_start_s: start_s,
        curious: true,
        points: curious_points(),
    }
}

fn begin_with(
    f: &Fixture,
    route: Resumed,
    here: [f64; 2],
    t: f64,
) -> (DowntimeWindow<'_>, Vec<WindowAction>) {
    let handover = Handover {
        resume: Some(route),
        ..Handover::first(margin())
    };
    DowntimeWindow::begin(f.setup(0, here, false), handover, at(t, 0.0))
}

#[test]
fn a_restarted_window_drives_on_with_what_is_left_of_its_predecessors_route() {
    let f = fixture();
    // Restarted halfway along the route's east leg (north 1 m, east 3 m, south).
    let here = [1.1, 1.15];
    let (w, actions) = begin_with(&f, resumed("goal1", 100.0), here, 20.0);
    assert_eq!(
        actions[0],
        WindowAction::Replanned {
            reason: Reason::Resumed
        },
        "{actions:?}"
    );
    let mission = sent(&actions);
    let route = curious_points();
    for p in &mission.waypoints {
        assert!(
            crate::path::off_path_m(*p, &route) < 1e-9,
            "{p:?} is not on the predecessor's route"
        );
        assert!(
            p[0] >= 1.1 - 1e-9,
            "{p:?}: the leg already driven is driven again"
        );
    }
    let last = mission.waypoints.last().copied().expect("waypoints");
    assert!(crate::path::distance(last, GOAL) < 1e-9, "ends at {last:?}");
    assert!(
        !actions
            .iter()
            .any(|a| matches!(a, WindowAction::RequestPlan(_))),
        "a resumed window asked for a new plan at once: {actions:?}"
    );
    let driving = w.driving().expect("driving");
    assert!(driving.curious && driving.task == "goal1");
    let end = driving.points.last().copied().expect("points");
    assert!(crate::path::distance(end, GOAL) < 1e-9, "kept to {end:?}");
}

#[test]
fn another_tasks_route_a_robot_off_the_route_or_a_route_too_long_begin_afresh() {
    let f = fixture();
    for (why, route, here, t) in [
        ("another task", resumed("goal2", 100.0), [1.1, 1.1], 20.0),
        ("another start", resumed("goal1", 90.0), [1.1, 1.1], 20.0),
        (
            "2 m off the route",
            resumed("goal1", 100.0),
            [1.1, 3.1],
            20.0,
        ),
        // 3 m and a turn left, 4 s to the task at 2 s/m.
        ("no time for it", resumed("goal1", 100.0), [1.1, 1.1], 96.0),
    ] {
        let (_, actions) = begin_with(&f, route, here, t);
        assert!(
            !actions.contains(&WindowAction::Replanned {
                reason: Reason::Resumed
            }),
            "{why}: resumed: {actions:?}"
        );
    }
}
