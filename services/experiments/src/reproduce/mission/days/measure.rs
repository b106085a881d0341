//! What a window is measured by: its time (driven, waited, held, early), its
//! information (driven, planned, shortest, change seen) and how well its time model
//! predicted the drive.

use roam_controller::controller::MissionStatus;
use serde::Serialize;

use super::robot::Step;
use super::world::DayWorld;
use roam_mission::information::gathered;
use roam_mission::path::distance;

/// One window of one variant's day.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct WindowResult {
    pub window: usize,
    pub task: String,
    /// When the window began (the previous task's end, or the day's first estimate)
    /// and the task's start, mission seconds; `window_s` is the difference.
    pub began_s: f64,
    pub task_start_s: f64,
    pub window_s: f64,
    /// When the robot reached the task's place; `None`: it never did (given up).
    pub arrival_s: Option<f64>,
    /// Arrived after the task's start, or never.
    pub late: bool,
    /// From the first mission sent to the arrival, seconds (0 when it never arrived):
    /// the executive's "driving time", holds for slack replans included.
    pub driving_s: f64,
    /// `driving_s / window_s`: the share of the window driven.
    pub share: f64,
    /// From the window's beginning to its first mission: the robot waited for the plan.
    pub waited_for_plan_s: f64,
    /// Held by the controller's PEB guard, in all (the executive's count), seconds;
    /// how many holds it acted on and how many recoveries it sent.
    pub held_s: f64,
    pub holds: u32,
    pub recoveries: u32,
    /// The first plan's probability of arriving late, as its margin bounds it.
    pub late_probability: Option<f64>,
    /// Waiting at the task's place before its start (arrived early), seconds.
    pub early_s: Option<f64>,
    /// The driving budget of the first plan (t_exec), seconds.
    pub budget_s: f64,
    /// The first plan was curious (else the shortest path: curiosity did not fit).
    pub curious: bool,
    /// Cells of the first plan (1: the robot was to stay where it was).
    pub first_plan_cells: usize,
    /// Curious plans the window asked for (its GA runs).
    pub ga_plans: u32,
    /// Paper 000's measure on the static map (distinct cells seen in the perception
    /// window): along the true driven path, along what the plans laid out (each
    /// replaced plan up to where the robot left it, the last one whole), and along the
    /// window's shortest path.
    pub driven_information: f64,
    pub planned_information: f64,
    pub shortest_information: f64,
    /// driven / planned; `None` when the plans promised nothing.
    pub driven_over_planned: Option<f64>,
    /// Cells that change during the day (the cart's) in the perception window of the
    /// true driven path.
    pub changing_cells_seen: f64,
    /// Mean PEB at the true positions along the drive (the field localization
    /// publishes; a cell without a fix counts 10 m), metres.
    pub peb_mean_m: Option<f64>,
    /// Steps the controller held the robot for its PEB.
    pub halted_steps: u64,
    /// RMS of the estimates' error along the drive (degraded estimates left out), metres.
    pub estimate_rms_m: Option<f64>,
    /// Each replan's reason, in order ([`roam_mission::watch::Reason::name`]).
    pub replans: Vec<&'static str>,
    /// The time model's prediction of the arrived mission.
    pub time_model: Option<TimeModelUse>,
}

/// How the window's time model predicted its last (arrived) mission.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct TimeModelUse {
    pub v_lin: f64,
    pub v_ang: f64,
    /// Eq. 2 on the mission's plan (its Σd and Σθ), seconds.
    pub predicted_s: f64,
    /// From sending the mission to the arrival, seconds.
    pub took_s: f64,
    /// (predicted − took) / took: positive when the model is pessimistic.
    pub error: f64,
}

/// The window's drive, step by step.
#[derive(Debug, Default)]
pub struct Track {
    pub truth: Vec<[f64; 2]>,
    peb_sum: f64,
    peb_n: u32,
    error2_sum: f64,
    error_n: u32,
    pub halted_steps: u64,
}

impl Track {
    pub fn record(&mut self, step: &Step, world: &DayWorld) {
        self.truth.push(step.truth);
        if let Some(c) = world.planning.cell_at(step.truth[0], step.truth[1]) {
            if let Some(&p) = world.planning.localizability.get(c as usize) {
                self.peb_sum += f64::from(p);
                self.peb_n += 1;
            }
        }
        if let Some(e) = step.estimate.as_ref().filter(|e| !e.degraded) {
            self.error2_sum += distance(e.position, step.truth).powi(2);
            self.error_n += 1;
        }
        if step
            .decision
            .is_some_and(|d| d.status == MissionStatus::HaltedPeb)
        {
            self.halted_steps += 1;
        }
    }

    pub fn peb_mean_m(&self) -> Option<f64> {
        (self.peb_n > 0).then(|| self.peb_sum / f64::from(self.peb_n))
    }

    pub fn estimate_rms_m(&self) -> Option<f64> {
        (self.error_n > 0).then(|| (self.error2_sum / f64::from(self.error_n)).sqrt())
    }

    /// Paper 000's measure of the driven path on the static map.
    pub fn information(&self, world: &DayWorld) -> f64 {
        gathered(&world.planning, &world.params, &self.truth)
    }

    /// The day's changing cells in the driven path's perception window.
    pub fn changing_cells_seen(&self, world: &DayWorld) -> f64 {
        gathered(&world.changing, &world.params, &self.truth)
    }
}

/// One mission of a window: its plan, and how far along it the controller got.
#[derive(Debug, Clone)]
pub struct Leg {
    /// The plan's cell centres.
    pub plan: Vec<[f64; 2]>,
    /// The distance left the controller reported first and last on this mission.
    first_left_m: Option<f64>,
    last_left_m: Option<f64>,
}

impl Leg {
    pub fn new(plan: Vec<[f64; 2]>) -> Leg {
        Leg {
            plan,
            first_left_m: None,
            last_left_m: None,
        }
    }

    /// The controller reports `left_m` to go on this mission.
    pub fn progress(&mut self, left_m: f64) {
        self.first_left_m.get_or_insert(left_m);
        self.last_left_m = Some(left_m);
    }

    /// The share of the mission driven when it was replaced: 1 − last / first distance
    /// left (0 when it was never driven).
    pub fn driven_share(&self) -> f64 {
        match (self.first_left_m, self.last_left_m) {
            (Some(first), Some(last)) if first > 0.0 => (1.0 - last / first).clamp(0.0, 1.0),
            _ => 0.0,
        }
    }
}

/// What a window's plans laid out for the robot: each replaced leg's plan up to the
/// share of it that was driven (by arc length), and the last leg whole when it arrived
/// (up to its share when it did not).
pub fn planned_path(legs: &[Leg], arrived: bool) -> Vec<[f64; 2]> {
    let mut out = Vec::new();
    for (i, leg) in legs.iter().enumerate() {
        let last = i + 1 == legs.len();
        let share = if last && arrived {
            1.0
        } else {
            leg.driven_share()
        };
        out.extend(prefix(&leg.plan, share));
    }
    out
}

/// The points of `points` within `share` of its length from its start (the first at
/// least).
fn prefix(points: &[[f64; 2]], share: f64) -> Vec<[f64; 2]> {
    let total: f64 = points.windows(2).map(|p| distance(p[0], p[1])).sum();
    let keep = share * total;
    let mut arc = 0.0;
    let mut out = Vec::new();
    for (i, &p) in points.iter().enumerate() {
        if i > 0 {
            arc += distance(points[i - 1], p);
        }
        if i > 0 && arc > keep + 1e-9 {
            break;
        }
        out.push(p);
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_replaced_leg_counts_up_to_where_it_was_left_and_the_last_whole() {
        let line: Vec<[f64; 2]> = (0..=10).map(|i| [f64::from(i), 0.0]).collect();
        let mut first = Leg::new(line.clone());
        first.progress(10.0);
        first.progress(7.0);
        assert!((first.driven_share() - 0.3).abs() < 1e-12);
        let back: Vec<[f64; 2]> = (0..=3).map(|i| [3.0, f64::from(i)]).collect();
        let second = Leg::new(back.clone());
        let path = planned_path(&[first.clone(), second.clone()], true);
        assert_eq!(path.len(), 4 + 4);
        assert_eq!(&path[..4], &line[..4]);
        assert_eq!(&path[4..], &back[..]);
        // Not arrived: the last leg was never driven, only its first point counts.
        assert_eq!(planned_path(&[first, second], false).len(), 4 + 1);
        assert_eq!(Leg::new(line).driven_share(), 0.0);
    }
}
