use super::*;
use crate::weights::Scheme;
use roam_localization::fim::FimOptions;
use roam_localization::model::RangingModel;
use roam_localization::ToaNoise;
use roam_proto::map::{GridMeta, Origin};
use roam_world::grid::{occupancy, Grid};

/// An empty 40 × 40 m map (0.5 m cells, origin 0) with four anchors around the
/// middle: covered everywhere near it.
pub(crate) fn fields() -> (Arc<ObstacleField>, Arc<InformationField>) {
    let meta = GridMeta {
        width: 80,
        height: 80,
        resolution: 0.5,
        origin: Origin::default(),
    };
    let obstacles = ObstacleField::new(&Grid::filled(meta, occupancy::FREE));
    let noise = ToaNoise {
        sigma_m: 0.1,
        d0_m: 15.0,
        k: 2.0,
    };
    let anchors = [[5.0, 5.0], [35.0, 5.0], [35.0, 35.0], [5.0, 35.0]];
    let model = RangingModel::new(&anchors, 30.0, noise).expect("model");
    (
        Arc::new(obstacles),
        Arc::new(InformationField::new(model, FimOptions::default())),
    )
}

fn controller(params: ApfParams) -> Controller {
    let (o, i) = fields();
    Controller::new(params, o, i)
}

fn plain() -> ApfParams {
    ApfParams {
        scheme: Scheme::Plain,
        ..ApfParams::default()
    }
}

const GOOD: Option<f64> = Some(0.1);

#[test]
fn idle_until_a_mission_and_after_an_empty_one() {
    let mut c = controller(plain());
    let d = c.update([20.0, 20.0], GOOD);
    assert_eq!(d.status, MissionState::Idle);
    assert_eq!((d.u, d.steps, d.waypoint), ([0.0, 0.0], 0, None));
    c.set_mission(vec![[25.0, 20.0]]);
    assert!(c.is_active());
    c.end_mission();
    assert_eq!(c.update([20.0, 20.0], GOOD).status, MissionState::Idle);
}

#[test]
fn active_drives_toward_the_waypoint_and_reports_the_distance_left() {
    let mut c = controller(plain());
    c.set_mission(vec![[23.0, 24.0], [23.0, 30.0]]);
    let d = c.update([20.0, 20.0], GOOD);
    assert_eq!(d.status, MissionState::Active);
    // Far from the walls: u = f_a = (0.6, 0.8).
    assert!((d.u[0] - 0.6).abs() < 1e-12 && (d.u[1] - 0.8).abs() < 1e-12);
    assert_eq!((d.waypoint, d.steps), (Some(0), 1));
    // 5 m to the first, 6 m more to the second.
    assert!((d.distance_left_m - 11.0).abs() < 1e-12);
    assert_eq!((d.omega_deg, d.z_isa), (0.0, 0.0));
}

#[test]
fn waypoints_within_g_thres_pass_in_the_same_update_then_completed() {
    let mut c = controller(plain());
    c.set_mission(vec![[20.0, 20.0], [20.05, 20.0], [25.0, 20.0]]);
    // The first two are within 0.1 m: the third is current at once.
    let d = c.update([20.0, 20.0], GOOD);
    assert_eq!((d.status, d.waypoint), (MissionState::Active, Some(2)));
    assert!((d.u[0] - 1.0).abs() < 1e-12);
    assert!((d.distance_left_m - 5.0).abs() < 1e-12);
    // 0.11 m short is not reached, 0.09 m short is (g_thres = 0.10 m).
    assert_eq!(c.update([24.89, 20.0], GOOD).waypoint, Some(2));
    let d = c.update([24.91, 20.0], GOOD);
    assert_eq!(d.status, MissionState::Completed);
    assert_eq!(
        (d.u, d.waypoint, d.distance_left_m),
        ([0.0, 0.0], None, 0.0)
    );
    assert_eq!(d.steps, 3);
    // Final: nothing changes any more.
    let again = c.update([0.0, 0.0], GOOD);
    assert_eq!((again.status, again.steps), (MissionState::Completed, 3));
}

#[test]
fn via_thres_loosens_every_waypoint_but_the_last() {
    let mut c = controller(ApfParams {
        via_thres_m: Some(0.5),
        ..plain()
    });
    c.set_mission(vec![[20.4, 20.0], [25.0, 20.0]]);
    // 0.4 m from the first: passed (via 0.5 m), the last is current.
    let d = c.update([20.0, 20.0], GOOD);
    assert_eq!(d.waypoint, Some(1));
    // The last still needs g_thres.
    assert_eq!(c.update([24.6, 20.0], GOOD).waypoint, Some(1));
    assert_eq!(
        c.update([24.95, 20.0], GOOD).status,
        MissionState::Completed
    );
}

#[test]
fn a_bad_or_lost_peb_holds_the_robot_until_it_is_good_again() {
    let mut c = controller(plain());
    c.set_mission(vec![[25.0, 20.0]]);
    for (peb, n) in [(None, 1), (Some(2.5), 2)] {
        let d = c.update([20.0, 20.0], peb);
        assert_eq!(d.status, MissionState::HaltedPeb);
        assert_eq!((d.u, d.halted_updates, d.steps), ([0.0, 0.0], n, n));
        assert!(c.is_active());
    }
    let d = c.update([20.0, 20.0], Some(2.0));
    assert_eq!((d.status, d.halted_updates), (MissionState::Active, 0));
    assert_eq!(d.u, [1.0, 0.0]);
}

#[test]
fn a_recovery_drives_through_a_bad_peb_and_the_next_mission_is_guarded_again() {
    let mut c = controller(plain());
    c.set_recovery(vec![[25.0, 20.0]]);
    let d = c.update([20.0, 20.0], None);
    assert_eq!((d.status, d.u), (MissionState::Active, [1.0, 0.0]));
    c.set_mission(vec![[25.0, 20.0]]);
    assert_eq!(c.update([20.0, 20.0], None).status, MissionState::HaltedPeb);
}

#[test]
fn an_infinite_bound_turns_the_guard_off() {
    let mut c = controller(ApfParams {
        max_peb_m: f64::INFINITY,
        ..plain()
    });
    c.set_mission(vec![[25.0, 20.0]]);
    for peb in [None, Some(1e9), Some(f64::NAN)] {
        assert_eq!(c.update([20.0, 20.0], peb).status, MissionState::Active);
    }
    // A non-finite position is always held.
    let d = c.update([f64::NAN, 20.0], GOOD);
    assert_eq!((d.status, d.u), (MissionState::HaltedPeb, [0.0, 0.0]));
}

#[test]
fn no_progress_over_the_window_is_stuck_but_halts_do_not_count() {
    let mut c = controller(ApfParams {
        stuck_window_steps: 10,
        stuck_min_progress_m: 0.25,
        ..plain()
    });
    c.set_mission(vec![[25.0, 20.0]]);
    // The first update sets the checkpoint (5 m); 0.2 m of progress is not enough.
    assert_eq!(c.update([20.0, 20.0], GOOD).status, MissionState::Active);
    for k in 1..10 {
        assert_eq!(
            c.update([20.0 + 0.02 * k as f64, 20.0], GOOD).status,
            MissionState::Active
        );
        // Halted updates do not advance the window.
        assert_eq!(c.update([20.0, 20.0], None).status, MissionState::HaltedPeb);
    }
    let d = c.update([20.2, 20.0], GOOD);
    assert_eq!(d.status, MissionState::Stuck);
    assert_eq!(d.u, [0.0, 0.0]);
    assert_eq!(d.steps, 20);
    assert_eq!(c.update([24.0, 20.0], GOOD).status, MissionState::Stuck);
    // A new mission starts afresh.
    c.set_mission(vec![[25.0, 20.0]]);
    let d = c.update([20.0, 20.0], GOOD);
    assert_eq!((d.status, d.steps), (MissionState::Active, 1));
}

#[test]
fn progress_moves_the_window() {
    let mut c = controller(ApfParams {
        stuck_window_steps: 10,
        ..plain()
    });
    c.set_mission(vec![[30.0, 20.0]]);
    // 0.3 m per 9 updates: progress every window, never stuck.
    for k in 0..100 {
        let x = 20.0 + 0.3 * (k / 9) as f64;
        assert_eq!(
            c.update([x, 20.0], GOOD).status,
            MissionState::Active,
            "{k}"
        );
    }
}

#[test]
fn the_step_limit_ends_the_mission() {
    let mut c = controller(ApfParams {
        max_steps: 3,
        ..plain()
    });
    c.set_mission(vec![[30.0, 20.0]]);
    for _ in 0..3 {
        assert_eq!(c.update([20.0, 20.0], GOOD).status, MissionState::Active);
    }
    let d = c.update([20.0, 20.0], GOOD);
    assert_eq!(
        (d.status, d.steps, d.u),
        (MissionState::StepLimit, 3, [0.0, 0.0])
    );
    assert_eq!(c.update([30.0, 20.0], GOOD).status, MissionState::StepLimit);
}

#[test]
fn walls_push_and_the_is_force_is_weighted_by_the_scheme() {
    // 1 m from the west edge (x = 0): f_Tr = (1 − 1/3)·(1, 0), times z_r = 20.
    let mut c = controller(plain());
    c.set_mission(vec![[1.0, 30.0]]);
    let d = c.update([1.0, 20.0], GOOD);
    assert!((d.u[0] - 20.0 * 2.0 / 3.0).abs() < 1e-6, "{:?}", d.u);
    assert!((d.u[1] - 1.0).abs() < 1e-9);
    // Fixed IS: u = f_a + 0.8 f_is, and ω is reported.
    let (o, i) = fields();
    let mut c = Controller::new(
        ApfParams {
            scheme: Scheme::Fixed,
            ..ApfParams::default()
        },
        o,
        i.clone(),
    );
    c.set_mission(vec![[30.0, 12.0]]);
    let p = [12.0, 12.0];
    let d = c.update(p, GOOD);
    let f_is = i.is_force(p);
    assert!((d.u[0] - (1.0 + 0.8 * f_is[0])).abs() < 1e-12);
    assert!((d.u[1] - 0.8 * f_is[1]).abs() < 1e-12);
    assert!((d.omega_deg - crate::forces::omega_deg([1.0, 0.0], f_is)).abs() < 1e-12);
    assert_eq!(d.z_isa, 0.8);
}

fn path_params() -> ApfParams {
    ApfParams {
        follow: Follow::Path,
        lookahead_m: 0.4,
        ..plain()
    }
}

#[test]
fn under_follow_path_f_a_pulls_toward_the_carrot_along_the_path() {
    let mut c = controller(path_params());
    // An L from where the robot is: east 4 m, then north 4 m.
    c.set_mission(vec![[22.0, 20.0], [24.0, 20.0], [24.0, 24.0]]);
    let d = c.update([20.0, 20.0], GOOD);
    assert_eq!((d.status, d.waypoint), (MissionState::Active, Some(0)));
    // On the path: the carrot is 0.4 m ahead, straight east.
    assert!(
        (d.u[0] - 1.0).abs() < 1e-12 && d.u[1].abs() < 1e-12,
        "{:?}",
        d.u
    );
    assert!((d.distance_left_m - 8.0).abs() < 1e-12);
    // A step at a time (the projection moves at most 2 L = 0.8 m per update), then
    // 0.3 m north of the first leg at x = 21: the carrot (21.4, 20) pulls back
    // toward the path, where f_a toward the waypoint (22, 20) would cut across.
    c.update([20.4, 20.0], GOOD);
    c.update([20.8, 20.0], GOOD);
    let d = c.update([21.0, 20.3], GOOD);
    let expect = crate::forces::attractive([21.0, 20.3], [21.4, 20.0]);
    assert!((d.u[0] - expect[0]).abs() < 1e-12 && (d.u[1] - expect[1]).abs() < 1e-12);
    assert!((d.distance_left_m - (0.3 + 7.0)).abs() < 1e-12);
    // Next to the corner: the carrot is round it and the reported waypoint is the one
    // ahead of the projection.
    for x in [21.6, 22.4, 23.2] {
        c.update([x, 20.0], GOOD);
    }
    let d = c.update([23.9, 20.0], GOOD);
    assert_eq!(d.waypoint, Some(1));
    let expect = crate::forces::attractive([23.9, 20.0], [24.0, 20.3]);
    assert!((d.u[0] - expect[0]).abs() < 1e-12 && (d.u[1] - expect[1]).abs() < 1e-12);
    c.update([24.0, 20.4], GOOD);
    let d = c.update([24.0, 21.0], GOOD);
    assert_eq!(d.waypoint, Some(2));
    assert!((d.u[1] - 1.0).abs() < 1e-12);
}

#[test]
fn under_follow_path_the_mission_completes_at_the_last_point_only() {
    let mut c = controller(path_params());
    // Out 3 m and back to 0.05 m from the start: the start is within g_thres of the
    // last point, but the carrot is not at the end yet.
    c.set_mission(vec![
        [23.0, 20.0],
        [23.0, 20.5],
        [20.05, 20.5],
        [20.05, 20.05],
    ]);
    let d = c.update([20.0, 20.0], GOOD);
    assert_eq!(d.status, MissionState::Active);
    // Along the way, then within g_thres of the end with the carrot there.
    for x in [20.4, 20.8, 21.2, 21.6, 22.0, 22.4, 22.8] {
        assert_eq!(c.update([x, 20.0], GOOD).status, MissionState::Active);
    }
    for p in [
        [23.0, 20.2],
        [22.6, 20.5],
        [22.2, 20.5],
        [21.8, 20.5],
        [21.4, 20.5],
    ] {
        assert_eq!(c.update(p, GOOD).status, MissionState::Active);
    }
    for x in [21.0, 20.6, 20.2] {
        assert_eq!(c.update([x, 20.5], GOOD).status, MissionState::Active);
    }
    // 0.11 m short is not reached; 0.09 m is.
    assert_eq!(c.update([20.05, 20.16], GOOD).status, MissionState::Active);
    let d = c.update([20.05, 20.14], GOOD);
    assert_eq!(d.status, MissionState::Completed);
    assert_eq!(
        (d.u, d.waypoint, d.distance_left_m),
        ([0.0, 0.0], None, 0.0)
    );
    // A one-waypoint mission where the robot stands is complete at once.
    c.set_mission(vec![[20.05, 20.0]]);
    assert_eq!(c.update([20.0, 20.0], GOOD).status, MissionState::Completed);
}

#[test]
fn under_follow_path_progress_along_the_path_is_what_the_stuck_rule_counts() {
    let mut c = controller(ApfParams {
        stuck_window_steps: 10,
        stuck_min_progress_m: 0.25,
        ..path_params()
    });
    c.set_mission(vec![[30.0, 20.0]]);
    // Sideways on the spot (no progress along the path): stuck after the window.
    for k in 0..10 {
        let y = if k % 2 == 0 { 20.1 } else { 19.9 };
        assert_eq!(
            c.update([20.0, y], GOOD).status,
            MissionState::Active,
            "{k}"
        );
    }
    assert_eq!(c.update([20.0, 20.1], GOOD).status, MissionState::Stuck);
    // 0.3 m along the path per 9 updates: never stuck.
    c.set_mission(vec![[40.0, 20.0]]);
    for k in 0..150 {
        let x = 10.0 + 0.3 * (k / 9) as f64;
        assert_eq!(
            c.update([x, 20.0], GOOD).status,
            MissionState::Active,
            "{k}"
        );
    }
}

#[test]
fn under_follow_path_a_waypoint_that_is_not_finite_is_left_out() {
    let mut c = controller(path_params());
    c.set_mission(vec![[f64::NAN, 0.0], [22.0, 20.0]]);
    let d = c.update([20.0, 20.0], GOOD);
    assert_eq!((d.status, d.waypoint), (MissionState::Active, Some(1)));
    assert!((d.u[0] - 1.0).abs() < 1e-12);
    c.set_mission(vec![[f64::INFINITY, 0.0]]);
    assert_eq!(c.update([20.0, 20.0], GOOD).status, MissionState::Completed);
}

#[test]
fn under_follow_path_the_path_starts_where_the_first_driven_update_is() {
    let mut c = controller(path_params());
    c.set_mission(vec![[24.0, 20.0]]);
    // Held for the PEB at first: the path starts at the first update that drives.
    assert_eq!(c.update([10.0, 10.0], None).status, MissionState::HaltedPeb);
    let d = c.update([20.0, 24.0], GOOD);
    // The carrot is 0.4 m along the segment (20, 24) → (24, 20): diagonal.
    let s = std::f64::consts::FRAC_1_SQRT_2;
    assert!(
        (d.u[0] - s).abs() < 1e-12 && (d.u[1] + s).abs() < 1e-12,
        "{:?}",
        d.u
    );
    assert!((d.distance_left_m - 32f64.sqrt()).abs() < 1e-12);
}
