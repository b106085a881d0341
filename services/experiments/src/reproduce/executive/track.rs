//! What a window's drive leaves behind for the measures: the robot's true track (its
//! PEB, its estimate errors, its halted steps) and its legs (each route sent, and how
//! far along it the controller got).

use roam_controller::controller::MissionState;
use roam_mission::information::gathered;
use roam_mission::path::distance;
use roam_planner::params::GaParams;
use roam_planner::world::World;

use super::step::Step;

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
    /// Records `step`, its PEB read off `planning` (the planner's map with
    /// localization's PEB field).
    pub fn record(&mut self, step: &Step, planning: &World) {
        self.truth.push(step.truth);
        if let Some(c) = planning.cell_at(step.truth[0], step.truth[1]) {
            if let Some(&p) = planning.localizability.get(c as usize) {
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
            .is_some_and(|d| d.status == MissionState::HaltedPeb)
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

    /// Paper 000's measure of the driven path on `map` (distinct cells seen, each
    /// worth its score).
    pub fn information(&self, map: &World, params: &GaParams) -> f64 {
        gathered(map, params, &self.truth)
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
