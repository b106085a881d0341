//! Per-robot tracking: one [`PositionEstimate`] per [`RangeScan`], each started from the
//! robot's last good fix (paper 002 §2.1's WLS localizer, run once per time step).
//!
//! The localization service publishes exactly what [`Tracker::on_scan`] returns, and the
//! controller's batch episodes call the same function: the one code path is what makes
//! "same seed, same trajectory, through the services and in batch" true.

use std::collections::HashMap;

use roam_proto::localization::PositionEstimate;
use roam_proto::sim::RangeScan;
use roam_world::scenario::SensingSpec;

use crate::fim::FimOptions;
use crate::model::RangingModel;
use crate::wls::{estimate, Range, WlsOptions};
use crate::LocalizationError;

/// Robots whose last estimate is kept as the next prior; a scan from a robot beyond this
/// many is still estimated, but from the closed-form start (no prior is stored for it).
pub const MAX_ROBOTS: usize = 1000;

/// Estimates robots' positions scan by scan, remembering each robot's last
/// non-degraded estimate as the prior of its next one.
#[derive(Debug, Clone)]
pub struct Tracker {
    sensing: SensingSpec,
    fim: FimOptions,
    priors: HashMap<String, [f64; 2]>,
}

impl Tracker {
    /// A tracker for the sensing model `sensing` (σ, d0, K, range; the anchors come with
    /// each scan) whose covariances follow `fim`.
    pub fn new(sensing: SensingSpec, fim: FimOptions) -> Tracker {
        Tracker {
            sensing,
            fim,
            priors: HashMap::new(),
        }
    }

    /// The estimate from one scan (paper 002 §2.1): the model is the scan's own anchors
    /// in scan order, the prior is the robot's last non-degraded estimate. A degraded
    /// estimate (too few or collinear anchors, no convergence) keeps the prior as its
    /// position and has no CRB and no PEB; it does not replace the prior.
    ///
    /// Refuses (an error, and nothing is remembered) a scan whose anchors or ranges are
    /// not finite or are too many.
    pub fn on_scan(&mut self, scan: &RangeScan) -> Result<PositionEstimate, LocalizationError> {
        let positions: Vec<[f64; 2]> = scan.ranges.iter().map(|r| r.at).collect();
        let model = RangingModel::from_spec(&positions, &self.sensing)?;
        let ranges: Vec<Range> = scan
            .ranges
            .iter()
            .enumerate()
            .map(|(anchor, r)| Range {
                anchor,
                range_m: r.range_m,
            })
            .collect();
        let prior = self.priors.get(&scan.robot).copied();
        let options = WlsOptions {
            fim: self.fim,
            ..WlsOptions::default()
        };
        let result = estimate(&model, &ranges, prior, &options)?;
        if !result.degraded
            && (self.priors.len() < MAX_ROBOTS || self.priors.contains_key(&scan.robot))
        {
            self.priors.insert(scan.robot.clone(), result.position);
        }
        let finite = result.peb.is_finite();
        let crb = result.covariance;
        Ok(PositionEstimate {
            robot: scan.robot.clone(),
            step: scan.step,
            time_s: scan.time_s,
            position: result.position,
            crb: finite.then(|| [[crb[(0, 0)], crb[(0, 1)]], [crb[(1, 0)], crb[(1, 1)]]]),
            peb_m: finite.then_some(result.peb),
            anchors_used: result
                .anchors_used
                .iter()
                .filter_map(|&i| scan.ranges.get(i).map(|r| r.anchor.clone()))
                .collect(),
            degraded: result.degraded,
        })
    }

    /// Forgets every robot's prior (a sim reset): the next scans start from the
    /// closed-form solution.
    pub fn reset(&mut self) {
        self.priors.clear();
    }

    /// The prior the next scan of `robot` starts from, if any.
    pub fn prior(&self, robot: &str) -> Option<[f64; 2]> {
        self.priors.get(robot).copied()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use roam_proto::sim::AnchorRange;

    fn scan(robot: &str, at: [f64; 2], anchors: &[[f64; 2]]) -> RangeScan {
        RangeScan {
            robot: robot.into(),
            step: 3,
            time_s: 1.2,
            ranges: anchors
                .iter()
                .enumerate()
                .map(|(i, a)| AnchorRange {
                    anchor: format!("a{i}"),
                    at: *a,
                    range_m: (a[0] - at[0]).hypot(a[1] - at[1]),
                })
                .collect(),
        }
    }

    #[test]
    fn a_good_fix_becomes_the_prior_and_a_degraded_one_keeps_it() {
        let mut t = Tracker::new(SensingSpec::default(), FimOptions::default());
        let anchors = [[0.0, 0.0], [10.0, 0.0], [0.0, 10.0]];
        let e = t
            .on_scan(&scan("r", [3.0, 4.0], &anchors))
            .expect("estimate");
        assert!(!e.degraded);
        assert!((e.position[0] - 3.0).abs() < 1e-6 && (e.position[1] - 4.0).abs() < 1e-6);
        assert_eq!((e.step, e.time_s), (3, 1.2));
        assert_eq!(e.anchors_used, ["a0", "a1", "a2"]);
        assert!(e.peb_m.is_some() && e.crb.is_some());
        let prior = t.prior("r").expect("prior");
        // Two anchors: degraded, the position is the prior, nothing is forgotten.
        let d = t
            .on_scan(&scan("r", [5.0, 5.0], &anchors[..2]))
            .expect("estimate");
        assert!(d.degraded);
        assert_eq!(d.position, prior);
        assert_eq!((d.peb_m, d.crb), (None, None));
        assert_eq!(t.prior("r"), Some(prior));
        assert_eq!(t.prior("other"), None);
        t.reset();
        assert_eq!(t.prior("r"), None);
    }

    #[test]
    fn a_bad_scan_is_refused() {
        let mut t = Tracker::new(SensingSpec::default(), FimOptions::default());
        let mut s = scan("r", [3.0, 4.0], &[[0.0, 0.0], [10.0, 0.0], [0.0, 10.0]]);
        s.ranges[1].range_m = f64::NAN;
        assert!(t.on_scan(&s).is_err());
        assert_eq!(t.prior("r"), None);
    }
}
