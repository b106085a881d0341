//! Fitting Eq. 2 (`t ≈ v_lin·d + v_ang·θ`) to the chunks of driven stretches.
//!
//! **Stops are told by time, not by stillness.** A robot that turns in place does not
//! move either, and its turning time is exactly what v_ang is; so "only count samples
//! while moving" would leave v_ang nothing to fit. Instead each stretch gets a robust
//! reference: v_lin is the lower quartile of time per metre over its straight chunks,
//! v_ang the lower quartile over its corners (of at least 0.25 rad) of the time left
//! after the distance, per radian; with fewer than 3 of a kind, the calibration's
//! current model stands in. (A quartile, not the median: waits only ever add time, and
//! they fall into corners, the longest chunks, more often than into straight chunks, so
//! in a stretch with many waits half of the corners can hold one.) A chunk is then
//!
//! - a **stop** (the robot waited: for a plan, a blocked way, the task) when it took
//!   longer than `(1 + stop_ratio)·t_ref + stop_slack_s` (defaults: one and a half
//!   times the reference's time plus 1 s), and is left out;
//! - a **jump** (a displaced robot, a localization jump) when it was faster than the
//!   fastest plausible robot (`min`'s v_lin and v_ang), and is left out;
//! - **driving** otherwise, and used.
//!
//! A wait shorter than that margin is not told apart from slow driving and counts. Each
//! stretch (a mission; a replan starts a new one) is measured on its own, so nothing is
//! fitted across a replan's jump in the path; its first chunk (and the first after a
//! gap in the samples) is always left out, counted as a stop: it holds the wait for the
//! plan and the turn toward the new path, which no chord before it lets the positions
//! see.
//!
//! **The fit.** Weighted least squares over the driving chunks, each weighted by the
//! inverse of its size, w = 1/(d + θ) (a radian counted as a metre; a chunk's timing
//! error grows with it), with the prior (Table I) blended in as two pseudo-chunks:
//! `prior_distance_m` = D0 metres of straight driving at the prior's v_lin and
//! `prior_turn_rad` = Θ0 radians of turning in place at its v_ang. In the normal
//! equations
//!
//! ```text
//! [ Σw·d² + D0    Σw·d·θ      ] [v_lin]   [ Σw·d·Δt + D0·v_lin0 ]
//! [ Σw·d·θ        Σw·θ² + Θ0  ] [v_ang] = [ Σw·θ·Δt + Θ0·v_ang0 ]
//! ```
//!
//! a ridge regression toward the prior, whose weight reads directly in metres and
//! radians: with straight driving only, v_lin is the distance-weighted mean of the
//! data's time per metre and the prior's, `(Σd·(Δt/d) + D0·v_lin0) / (Σd + D0)`, and
//! v_ang stays the prior's; turns in place likewise for v_ang with Θ0. (A corner chunk
//! also holds distance, so it counts for less than its radians.) With no data the fit is
//! the prior; with the defaults (5 m, a right angle) one metre moves v_lin a sixth of
//! the way to the data. For a robot far from Table I (1.25 s/m, 1.67 s/rad; the sim
//! test, `tests/calibration.rs`) a clean zig-zag of 140 m with 38 corners ends about 5%
//! off the truth, 290 m with 77 corners about 2.3%, 430 m with 116 corners about 1.5%.
//! The weights do not depend on any model, so the sums can be kept and added to. The
//! solution is clamped to `min..=max`; when one of the two is clamped the other is refit
//! given it. A solution that is not a number (it cannot be while D0 and Θ0 are
//! positive) falls back to the prior.
//!
//! **Memory.** The sums (not the samples) are kept, so a calibration has a fixed size.
//! When they hold more than `memory_s` seconds of driving they are scaled down to it:
//! older driving fades, so a robot whose speed changes is followed.

use serde::{Deserialize, Serialize};

use super::config::CalibrationConfig;
use super::error::CalibrationError;
use super::stretch::{chunks, Chunk, Stretch};
use super::time_model::TimeModel;

/// The fewest chunks of a kind (straight, corner) for a stretch's own reference.
const MIN_REFERENCE_CHUNKS: usize = 3;

/// The quantile of a stretch's chunks its reference is taken at (the lower quartile).
const REFERENCE_QUANTILE: f64 = 0.25;

/// The least turn of a corner that the reference's v_ang is taken from, radians.
const MIN_REFERENCE_TURN_RAD: f64 = 0.25;

/// The sufficient statistics of the fit: the normal equations' sums over the driving
/// chunks (w = 1/(d + θ)), and counters.
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Statistics {
    /// Σ w·d², Σ w·d·θ, Σ w·θ² (metres and radians, a radian counted as a metre).
    pub dd: f64,
    pub dtheta: f64,
    pub thetatheta: f64,
    /// Σ w·d·Δt and Σ w·θ·Δt (seconds).
    pub dt: f64,
    pub thetat: f64,
    /// Seconds of driving the sums hold (after forgetting).
    pub seconds: f64,
    /// Chunks used, stops and jumps left out, stretches added: never forgotten.
    pub chunks: u64,
    pub stops: u64,
    pub jumps: u64,
    pub stretches: u64,
}

impl Statistics {
    fn add(&mut self, c: &Chunk) {
        let (d, theta, t) = (c.distance_m, c.turn_rad, c.duration_s);
        let w = 1.0 / (d + theta);
        self.dd += w * d * d;
        self.dtheta += w * d * theta;
        self.thetatheta += w * theta * theta;
        self.dt += w * d * t;
        self.thetat += w * theta * t;
        self.seconds += c.duration_s;
        self.chunks = self.chunks.saturating_add(1);
    }

    fn forget(&mut self, memory_s: f64) {
        if self.seconds > memory_s {
            let f = memory_s / self.seconds;
            for v in [
                &mut self.dd,
                &mut self.dtheta,
                &mut self.thetatheta,
                &mut self.dt,
                &mut self.thetat,
                &mut self.seconds,
            ] {
                *v *= f;
            }
        }
    }

    /// Whether these could have come from [`Calibration::add`]: finite, non-negative
    /// where they must be, the normal matrix positive semi-definite.
    pub fn is_plausible(&self) -> bool {
        let sums = [
            self.dd,
            self.dtheta,
            self.thetatheta,
            self.dt,
            self.thetat,
            self.seconds,
        ];
        sums.iter().all(|v| v.is_finite() && *v >= 0.0)
            && self.dtheta * self.dtheta <= self.dd * self.thetatheta * (1.0 + 1e-9) + 1e-300
    }
}

/// What a chunk was.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Kind {
    Driving,
    Stop,
    Jump,
}

fn lower_quartile(mut values: Vec<f64>) -> Option<f64> {
    values.retain(|v| v.is_finite());
    if values.len() < MIN_REFERENCE_CHUNKS {
        return None;
    }
    values.sort_by(f64::total_cmp);
    let at = (REFERENCE_QUANTILE * (values.len() - 1) as f64).round() as usize;
    values.get(at).copied()
}

fn clamp(model: TimeModel, config: &CalibrationConfig) -> TimeModel {
    TimeModel {
        v_lin: model.v_lin.clamp(config.min.v_lin, config.max.v_lin),
        v_ang: model.v_ang.clamp(config.min.v_ang, config.max.v_ang),
    }
}

/// A stretch's robust reference (see the module): its own lower quartiles, `fallback`
/// where it has too few chunks of a kind.
fn reference(chunks: &[Chunk], fallback: TimeModel, config: &CalibrationConfig) -> TimeModel {
    let driven = || chunks.iter().filter(|c| !c.leading);
    let straight = driven()
        .filter(|c| c.turn_rad == 0.0)
        .map(|c| c.duration_s / c.distance_m)
        .collect();
    let v_lin = lower_quartile(straight)
        .unwrap_or(fallback.v_lin)
        .clamp(config.min.v_lin, config.max.v_lin);
    let corners = driven()
        .filter(|c| c.turn_rad >= MIN_REFERENCE_TURN_RAD)
        .map(|c| (c.duration_s - v_lin * c.distance_m) / c.turn_rad)
        .collect();
    let v_ang = lower_quartile(corners).unwrap_or(fallback.v_ang);
    clamp(TimeModel { v_lin, v_ang }, config)
}

fn kind(c: &Chunk, reference: TimeModel, config: &CalibrationConfig) -> Kind {
    let fastest = config.min.eta(c.distance_m, c.turn_rad);
    // Written so that a NaN duration is a jump, never driving.
    if !(c.duration_s >= fastest && c.duration_s > 0.0) {
        return Kind::Jump;
    }
    let expected = reference.eta(c.distance_m, c.turn_rad);
    if c.duration_s > (1.0 + config.stop_ratio) * expected + config.stop_slack_s {
        Kind::Stop
    } else {
        Kind::Driving
    }
}

/// The chunks of `stretch` with what each was, judged against the stretch's reference.
fn judged(
    stretch: &Stretch,
    fallback: TimeModel,
    config: &CalibrationConfig,
) -> Vec<(Chunk, Kind)> {
    let chunks = chunks(stretch, config);
    let reference = reference(&chunks, fallback, config);
    chunks
        .into_iter()
        .map(|c| {
            let k = if c.leading {
                Kind::Stop
            } else {
                kind(&c, reference, config)
            };
            (c, k)
        })
        .collect()
}

/// The prior-blended weighted least squares (see the module), clamped.
fn solve(s: &Statistics, prior: TimeModel, config: &CalibrationConfig) -> TimeModel {
    let (d0, theta0) = (config.prior_distance_m, config.prior_turn_rad);
    let a00 = s.dd + d0;
    let a01 = s.dtheta;
    let a11 = s.thetatheta + theta0;
    let b0 = s.dt + d0 * prior.v_lin;
    let b1 = s.thetat + theta0 * prior.v_ang;
    let det = a00 * a11 - a01 * a01;
    if !(det.is_finite() && det > 0.0) {
        return clamp(prior, config);
    }
    let v_lin = (b0 * a11 - b1 * a01) / det;
    let v_ang = (a00 * b1 - a01 * b0) / det;
    if !(v_lin.is_finite() && v_ang.is_finite()) {
        return clamp(prior, config);
    }
    let lin_in = (config.min.v_lin..=config.max.v_lin).contains(&v_lin);
    let ang_in = (config.min.v_ang..=config.max.v_ang).contains(&v_ang);
    let (lo, hi) = (config.min, config.max);
    match (lin_in, ang_in) {
        (true, true) => TimeModel { v_lin, v_ang },
        (false, true) => {
            let v_lin = v_lin.clamp(lo.v_lin, hi.v_lin);
            let v_ang = ((b1 - a01 * v_lin) / a11).clamp(lo.v_ang, hi.v_ang);
            TimeModel { v_lin, v_ang }
        }
        (true, false) => {
            let v_ang = v_ang.clamp(lo.v_ang, hi.v_ang);
            let v_lin = ((b0 - a01 * v_ang) / a00).clamp(lo.v_lin, hi.v_lin);
            TimeModel { v_lin, v_ang }
        }
        (false, false) => clamp(TimeModel { v_lin, v_ang }, config),
    }
}

/// What one stretch added.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct StretchSummary {
    /// Driving chunks used, and what they hold.
    pub chunks: usize,
    pub distance_m: f64,
    pub turn_rad: f64,
    pub driving_s: f64,
    /// Chunks left out as stops, and their seconds.
    pub stops: usize,
    pub stopped_s: f64,
    /// Chunks left out as jumps.
    pub jumps: usize,
}

/// One robot's calibration: a prior, the fit's sums, and how it measures.
#[derive(Debug, Clone, PartialEq)]
pub struct Calibration {
    prior: TimeModel,
    config: CalibrationConfig,
    statistics: Statistics,
}

impl Calibration {
    /// No data yet: the model is `prior` (Table I: [`TimeModel::table_i`]). Refused
    /// when `config` or `prior` is out of range.
    pub fn new(
        prior: TimeModel,
        config: CalibrationConfig,
    ) -> Result<Calibration, CalibrationError> {
        config.check()?;
        prior.check("prior", &config)?;
        Ok(Calibration {
            prior,
            config,
            statistics: Statistics::default(),
        })
    }

    /// This calibration with `statistics` (restored from a file, already checked).
    pub(crate) fn with_statistics(mut self, statistics: Statistics) -> Calibration {
        self.statistics = statistics;
        self
    }

    /// Adds one stretch (a mission's samples): its driving chunks go into the fit, its
    /// stops and jumps are left out.
    /// Adds one driven plan in the planner's own terms: the plan's Σd and Σθ as Eq. 2
    /// counts them on its cells ([`crate::calibration::path_measure`]) and how long the
    /// robot took to drive it, seconds. This is what makes the planner's ETA predict the
    /// robot: the 8-connected path's 45° steps are turns the robot smooths away, so
    /// v_ang fitted to what the robot turned would not price the planner's Σθ. Refused
    /// (false, nothing added) when a figure is not finite or the plan is empty.
    pub fn add_planned(&mut self, distance_m: f64, turn_rad: f64, duration_s: f64) -> bool {
        let usable = [distance_m, turn_rad, duration_s]
            .iter()
            .all(|v| v.is_finite() && *v >= 0.0)
            && distance_m + turn_rad > 0.0;
        if !usable {
            return false;
        }
        self.statistics.add(&Chunk {
            distance_m,
            turn_rad,
            duration_s,
            leading: false,
        });
        self.statistics.stretches = self.statistics.stretches.saturating_add(1);
        self.statistics.forget(self.config.memory_s);
        true
    }

    pub fn add(&mut self, stretch: &Stretch) -> StretchSummary {
        let mut summary = StretchSummary::default();
        for (c, kind) in judged(stretch, self.model(), &self.config) {
            match kind {
                Kind::Driving => {
                    self.statistics.add(&c);
                    summary.chunks += 1;
                    summary.distance_m += c.distance_m;
                    summary.turn_rad += c.turn_rad;
                    summary.driving_s += c.duration_s;
                }
                Kind::Stop => {
                    summary.stops += 1;
                    summary.stopped_s += c.duration_s;
                }
                Kind::Jump => summary.jumps += 1,
            }
        }
        let s = &mut self.statistics;
        s.stops = s.stops.saturating_add(summary.stops as u64);
        s.jumps = s.jumps.saturating_add(summary.jumps as u64);
        s.stretches = s.stretches.saturating_add(1);
        s.forget(self.config.memory_s);
        summary
    }

    /// The calibrated model: the prior blended with everything added (see the module).
    pub fn model(&self) -> TimeModel {
        solve(&self.statistics, self.prior, &self.config)
    }

    pub fn prior(&self) -> TimeModel {
        self.prior
    }

    pub fn config(&self) -> &CalibrationConfig {
        &self.config
    }

    pub fn statistics(&self) -> &Statistics {
        &self.statistics
    }
}

/// The calibrated model of `stretches` from `prior`: [`Calibration::add`] on each, in
/// order, then [`Calibration::model`].
pub fn fit(
    prior: TimeModel,
    stretches: &[Stretch],
    config: CalibrationConfig,
) -> Result<TimeModel, CalibrationError> {
    let mut calibration = Calibration::new(prior, config)?;
    for s in stretches {
        calibration.add(s);
    }
    Ok(calibration.model())
}

/// How well a model predicted a window's driving: Eq. 2 on what was driven against the
/// time it took, stops left out (judged as [`Calibration::add`] judges them, with the
/// model itself as the fallback reference).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct WindowError {
    /// Driven, in the driving chunks: metres and radians.
    pub distance_m: f64,
    pub turn_rad: f64,
    /// `model.eta(distance_m, turn_rad)`, seconds.
    pub predicted_s: f64,
    /// The driving chunks' time, seconds.
    pub measured_s: f64,
    /// predicted − measured: positive when the model is pessimistic (the robot arrives
    /// early and waits), negative when it is optimistic (the robot is late).
    pub error_s: f64,
    /// `error_s / measured_s`; `None` when nothing was driven.
    pub relative: Option<f64>,
    /// Seconds in chunks left out as stops.
    pub stopped_s: f64,
    pub chunks: usize,
    pub stops: usize,
    pub jumps: usize,
}

impl TimeModel {
    /// The prediction error of this model over a window's `stretches` (its missions).
    pub fn window_error(
        &self,
        stretches: &[Stretch],
        config: &CalibrationConfig,
    ) -> Result<WindowError, CalibrationError> {
        config.check()?;
        self.check("model", config)?;
        let mut e = WindowError {
            distance_m: 0.0,
            turn_rad: 0.0,
            predicted_s: 0.0,
            measured_s: 0.0,
            error_s: 0.0,
            relative: None,
            stopped_s: 0.0,
            chunks: 0,
            stops: 0,
            jumps: 0,
        };
        for stretch in stretches {
            for (c, kind) in judged(stretch, *self, config) {
                match kind {
                    Kind::Driving => {
                        e.chunks += 1;
                        e.distance_m += c.distance_m;
                        e.turn_rad += c.turn_rad;
                        e.measured_s += c.duration_s;
                    }
                    Kind::Stop => {
                        e.stops += 1;
                        e.stopped_s += c.duration_s;
                    }
                    Kind::Jump => e.jumps += 1,
                }
            }
        }
        e.predicted_s = self.eta(e.distance_m, e.turn_rad);
        e.error_s = e.predicted_s - e.measured_s;
        e.relative = (e.measured_s > 0.0).then(|| e.error_s / e.measured_s);
        Ok(e)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn driven_plans_in_the_planners_terms_recover_the_model() {
        let truth = TimeModel {
            v_lin: 1.2,
            v_ang: 0.3,
        };
        let mut c = Calibration::new(TimeModel::table_i(), CalibrationConfig::default())
            .expect("calibration");
        // Three days of eight windows. plans: 20-35 m with 5-50 rad of the cell path's turning, the
        // two varied apart (a day has straight trips and winding curious ones).
        for i in 0..24u32 {
            let d = 20.0 + 5.0 * f64::from(i % 4);
            let theta = if i % 2 == 0 { 5.0 } else { 50.0 } + f64::from(i);
            assert!(c.add_planned(d, theta, truth.eta(d, theta)));
        }
        // Measured: v_lin +2.7%, v_ang -6.0%. A plan's Σd and Σθ grow together (a
        // longer plan turns more), so the prior's 5 m at Table I's 2 s/m still pulls
        // after 24 plans; exact data without a prior gives the truth.
        let m = c.model();
        assert!((m.v_lin / truth.v_lin - 1.0).abs() < 0.05, "{m:?}");
        assert!((m.v_ang / truth.v_ang - 1.0).abs() < 0.10, "{m:?}");
        assert!(!c.add_planned(f64::NAN, 1.0, 1.0));
        assert!(!c.add_planned(0.0, 0.0, 1.0));
    }

    fn chunk(d: f64, theta: f64, t: f64) -> Chunk {
        Chunk {
            distance_m: d,
            turn_rad: theta,
            duration_s: t,
            leading: false,
        }
    }

    #[test]
    fn no_data_is_the_prior_and_straight_driving_leaves_v_ang_alone() {
        let config = CalibrationConfig::default();
        let prior = TimeModel::table_i();
        assert_eq!(solve(&Statistics::default(), prior, &config), prior);
        let mut s = Statistics::default();
        for _ in 0..100 {
            s.add(&chunk(0.5, 0.0, 0.5));
        }
        let m = solve(&s, prior, &config);
        assert!((m.v_ang - prior.v_ang).abs() < 1e-12, "{m:?}");
        // 50 m at 1 s/m against 5 m at 2 s/m: (50 + 10) / (50 + 5) s/m.
        assert!((m.v_lin - 60.0 / 55.0).abs() < 1e-12, "{m:?}");
    }

    #[test]
    fn exact_data_is_recovered_and_outliers_are_judged() {
        let config = CalibrationConfig::default();
        let truth = TimeModel {
            v_lin: 1.25,
            v_ang: 3.0,
        };
        let mut s = Statistics::default();
        let mut chunks = Vec::new();
        for k in 0..2000 {
            let (d, theta) = (0.5 + f64::from(k % 7) * 0.1, f64::from(k % 3) * 0.8);
            chunks.push(chunk(d, theta, truth.eta(d, theta)));
        }
        for c in &chunks {
            s.add(c);
        }
        // 1,600 m and 1,100 rad of data against the prior's 5 m and π/2 rad: within 2%.
        let m = solve(&s, TimeModel::table_i(), &config);
        assert!(
            (m.v_lin / truth.v_lin - 1.0).abs() < 0.02
                && (m.v_ang / truth.v_ang - 1.0).abs() < 0.02,
            "{m:?}"
        );
        let r = reference(&chunks, TimeModel::table_i(), &config);
        assert!(
            (r.v_lin - 1.25).abs() < 1e-9 && (r.v_ang - 3.0).abs() < 1e-9,
            "{r:?}"
        );
        assert_eq!(kind(&chunk(1.0, 0.0, 1.3), r, &config), Kind::Driving);
        assert_eq!(kind(&chunk(1.0, 0.0, 10.0), r, &config), Kind::Stop);
        assert_eq!(kind(&chunk(1.0, 0.0, 0.01), r, &config), Kind::Jump);
        assert_eq!(kind(&chunk(1.0, 0.0, f64::NAN), r, &config), Kind::Jump);
    }

    #[test]
    fn the_fit_is_clamped_and_never_nan() {
        let config = CalibrationConfig::default();
        let mut s = Statistics::default();
        // Absurdly slow straight driving: 100 s per metre.
        for _ in 0..1000 {
            s.add(&chunk(1.0, 0.0, 100.0));
        }
        let m = solve(&s, TimeModel::table_i(), &config);
        assert_eq!(m.v_lin, config.max.v_lin);
        assert!(m.v_ang.is_finite());
        let nan = Statistics {
            dd: f64::NAN,
            ..Statistics::default()
        };
        assert!(!nan.is_plausible());
        assert_eq!(
            solve(&nan, TimeModel::table_i(), &config),
            TimeModel::table_i()
        );
    }

    #[test]
    fn memory_keeps_the_sums_bounded_and_follows_a_change() {
        let config = CalibrationConfig {
            memory_s: 100.0,
            ..CalibrationConfig::default()
        };
        let mut s = Statistics::default();
        for _ in 0..1000 {
            s.add(&chunk(1.0, 0.0, 2.0));
            s.forget(config.memory_s);
        }
        for _ in 0..1000 {
            s.add(&chunk(1.0, 0.0, 1.0));
            s.forget(config.memory_s);
        }
        assert!(s.seconds <= 100.0 + 1e-9);
        let m = solve(&s, TimeModel::table_i(), &config);
        assert!((m.v_lin - 1.0).abs() < 0.1, "the recent speed wins: {m:?}");
    }
}
