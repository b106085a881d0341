//! Why a run failed, measured from its track, so a reproduction can say which failures
//! are paper 002's and which are roam's.
//!
//! Paper 002 §4 (ES1) says plain APF and cutoff "navigate to an area with insufficient
//! sensing coverage and cannot complete their mission". roam adds a PEB guard (not in the
//! paper, `ApfParams::max_peb_m`): a robot without a fix is held. With the guard on, a
//! robot that loses its fix is held until it is given up, which is a failure roam causes;
//! whether the robot would have failed without the guard only a run with the guard off
//! (`max_peb_m = ∞`) shows. So every failed run is put in exactly one class, in this
//! order:
//!
//! 1. [`FailureCause::WrongFirstFix`]: the robot's very first estimate was more than
//!    [`DIVERGED_M`] off (the range equations' second solution, see [`super::es1`]); such
//!    a run fails with the guard (held at the start) and without it (driven on the wrong
//!    position), so it is neither the paper's failure nor the guard's;
//! 2. [`FailureCause::HeldByGuard`]: the guard was holding the robot when its mission
//!    ended (roam's failure, whatever brought the robot there);
//! 3. [`FailureCause::OutOfCoverage`]: the robot was driving and ended where fewer than
//!    three anchors are in range (paper 002 §4: "insufficient sensing coverage" — the
//!    paper's failure);
//! 4. [`FailureCause::EstimateDiverged`]: it ended in coverage but its estimate was more
//!    than [`DIVERGED_M`] off;
//! 5. [`FailureCause::Other`]: in coverage on a good estimate (a local minimum, an
//!    oscillation: the step limit or the stuck rule).
//!
//! For a held run the coverage at the end is counted beside it
//! ([`FailureCauses::held_out_of_coverage`]): a robot held where fewer than three anchors
//! reach it did drive into poor coverage first, the paper's situation, before the guard
//! turned it into a hold.

use serde::Serialize;

use crate::closed_loop::episode::{Episode, RobotTrack, Setup};

/// An estimate this far from the truth at the end of a failed run counts as diverged,
/// metres: 2.5 times roam's PEB bound of 2 m, and far below the tens of metres of a fix
/// on the wrong solution.
pub const DIVERGED_M: f64 = 5.0;

/// Paper 002 §4: "well covered areas (within the sensing range of at least 3 anchors)".
pub const MIN_COVERAGE: usize = 3;

/// Why a run failed (module doc).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum FailureCause {
    WrongFirstFix,
    HeldByGuard {
        /// Fewer than [`MIN_COVERAGE`] anchors in range where the robot was held.
        out_of_coverage: bool,
    },
    OutOfCoverage,
    EstimateDiverged,
    Other,
}

/// How many failed runs fell in each class (module doc).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize)]
pub struct FailureCauses {
    /// The first estimate more than [`DIVERGED_M`] off.
    pub wrong_first_fix: usize,
    /// Held by roam's PEB guard when the mission ended.
    pub held_by_guard: usize,
    /// Of `held_by_guard`, those held where fewer than three anchors reach the robot.
    pub held_out_of_coverage: usize,
    /// Driving, and ended where fewer than three anchors reach the robot (the paper's).
    pub out_of_coverage: usize,
    /// Ended in coverage with the estimate more than [`DIVERGED_M`] off.
    pub estimate_diverged: usize,
    /// Ended in coverage on a good estimate.
    pub other: usize,
    /// Not a cause of failure: scans localization refused over all the runs (successful
    /// ones too), 0 on a healthy run.
    pub localization_errors: u64,
}

impl FailureCauses {
    /// Counts `causes` (one per failed run).
    pub fn count(causes: impl IntoIterator<Item = FailureCause>) -> FailureCauses {
        let mut c = FailureCauses::default();
        for cause in causes {
            match cause {
                FailureCause::WrongFirstFix => c.wrong_first_fix += 1,
                FailureCause::HeldByGuard { out_of_coverage } => {
                    c.held_by_guard += 1;
                    c.held_out_of_coverage += usize::from(out_of_coverage);
                }
                FailureCause::OutOfCoverage => c.out_of_coverage += 1,
                FailureCause::EstimateDiverged => c.estimate_diverged += 1,
                FailureCause::Other => c.other += 1,
            }
        }
        c
    }

    /// The two counts added class by class (ES3: over its missions).
    pub fn plus(&self, other: &FailureCauses) -> FailureCauses {
        FailureCauses {
            wrong_first_fix: self.wrong_first_fix + other.wrong_first_fix,
            held_by_guard: self.held_by_guard + other.held_by_guard,
            held_out_of_coverage: self.held_out_of_coverage + other.held_out_of_coverage,
            out_of_coverage: self.out_of_coverage + other.out_of_coverage,
            estimate_diverged: self.estimate_diverged + other.estimate_diverged,
            other: self.other + other.other,
            localization_errors: self.localization_errors + other.localization_errors,
        }
    }

    /// The failed runs counted (each in exactly one class).
    pub fn total(&self) -> usize {
        self.wrong_first_fix
            + self.held_by_guard
            + self.out_of_coverage
            + self.estimate_diverged
            + self.other
    }
}

/// Why `track` failed (module doc); `None` when it succeeded.
pub fn robot_cause(track: &RobotTrack, setup: &Setup) -> Option<FailureCause> {
    if track.success {
        return None;
    }
    let off = |e: &f64| e.is_nan() || *e > DIVERGED_M;
    if track.error_m.first().is_some_and(off) {
        return Some(FailureCause::WrongFirstFix);
    }
    let covered = track
        .truth
        .last()
        .is_some_and(|&p| setup.information.coverage(p) >= MIN_COVERAGE);
    if track.held_updates > 0 {
        return Some(FailureCause::HeldByGuard {
            out_of_coverage: !covered,
        });
    }
    if !covered {
        return Some(FailureCause::OutOfCoverage);
    }
    Some(if track.error_m.last().is_some_and(off) {
        FailureCause::EstimateDiverged
    } else {
        FailureCause::Other
    })
}

/// Why `episode` failed: its first failed robot's cause; `None` when every robot
/// succeeded.
pub fn cause(episode: &Episode, setup: &Setup) -> Option<FailureCause> {
    episode
        .robots
        .iter()
        .find_map(|track| robot_cause(track, setup))
}

#[cfg(test)]
mod tests {
    use std::path::Path;

    use super::*;
    use crate::closed_loop::episode::load_scenario;
    use roam_controller::controller::MissionState;

    fn es1() -> Setup {
        let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../config/scenarios/es1.yaml");
        Setup::new(&load_scenario(&path).expect("scenario")).expect("setup")
    }

    /// A = (10, 16) hears a1, a2 and a4; the route's middle (35, 16) only the pair.
    const COVERED: [f64; 2] = [10.0, 16.0];
    const UNCOVERED: [f64; 2] = [35.0, 16.0];

    fn track(success: bool, at: [f64; 2], error_m: f64, held_updates: u64) -> RobotTrack {
        track_from(0.1, success, at, error_m, held_updates)
    }

    fn track_from(
        first_error_m: f64,
        success: bool,
        at: [f64; 2],
        error_m: f64,
        held_updates: u64,
    ) -> RobotTrack {
        RobotTrack {
            robot: "robot".into(),
            waypoints: vec![[60.0, 16.0]],
            status: if success {
                MissionState::Completed
            } else {
                MissionState::StepLimit
            },
            success,
            steps: 10,
            distance_m: 1.0,
            truth: vec![COVERED, at],
            estimate: vec![COVERED, at],
            error_m: vec![first_error_m, error_m],
            held_updates,
        }
    }

    #[test]
    fn each_failure_lands_in_its_class() {
        let setup = es1();
        assert!(setup.information.coverage(COVERED) >= MIN_COVERAGE);
        assert!(setup.information.coverage(UNCOVERED) < MIN_COVERAGE);
        let cause = |t: RobotTrack| robot_cause(&t, &setup);
        assert_eq!(cause(track(true, UNCOVERED, 50.0, 3)), None);
        // A wrong first fix comes before the guard and the coverage.
        assert_eq!(
            cause(track_from(45.0, false, UNCOVERED, 60.0, 3)),
            Some(FailureCause::WrongFirstFix)
        );
        assert_eq!(
            cause(track_from(f64::NAN, false, COVERED, 0.1, 0)),
            Some(FailureCause::WrongFirstFix)
        );
        assert_eq!(cause(track_from(45.0, true, COVERED, 0.1, 0)), None);
        assert_eq!(
            cause(track(false, UNCOVERED, 0.1, 3)),
            Some(FailureCause::HeldByGuard {
                out_of_coverage: true
            })
        );
        assert_eq!(
            cause(track(false, COVERED, 50.0, 1)),
            Some(FailureCause::HeldByGuard {
                out_of_coverage: false
            })
        );
        assert_eq!(
            cause(track(false, UNCOVERED, 50.0, 0)),
            Some(FailureCause::OutOfCoverage)
        );
        assert_eq!(
            cause(track(false, COVERED, 30.0, 0)),
            Some(FailureCause::EstimateDiverged)
        );
        assert_eq!(
            cause(track(false, COVERED, f64::NAN, 0)),
            Some(FailureCause::EstimateDiverged)
        );
        assert_eq!(
            cause(track(false, COVERED, 0.5, 0)),
            Some(FailureCause::Other)
        );
        let counted = FailureCauses::count([
            FailureCause::WrongFirstFix,
            FailureCause::HeldByGuard {
                out_of_coverage: true,
            },
            FailureCause::HeldByGuard {
                out_of_coverage: false,
            },
            FailureCause::OutOfCoverage,
            FailureCause::Other,
        ]);
        assert_eq!(
            (
                counted.wrong_first_fix,
                counted.held_by_guard,
                counted.held_out_of_coverage,
                counted.out_of_coverage,
                counted.estimate_diverged,
                counted.other,
                counted.total()
            ),
            (1, 2, 1, 1, 0, 1, 5)
        );
    }
}
