//! What the robot drove, measured the way paper 000's Eq. 2 counts a path: distance and
//! absolute heading change, cut into chunks that a time fit can use.
//!
//! **Resampling.** Positions (estimates or ground truth) are noisy, and Eq. 2's Σθ sums
//! absolute heading changes, which noise only ever adds to. So the samples are first
//! resampled by distance: a *knot* is kept each time the robot is `spacing_m` from the
//! last knot (while it stands or turns in place, no knot is made). Knot to knot is a
//! *chord*; at each inner knot the heading changes by the signed angle α between its two
//! chords.
//!
//! **Chunks.** A knot with |α| below `straight_rad` is on a straight line (its α is
//! noise and is not counted); a maximal run of knots turning the same way at or above it
//! is a *corner*. A corner's turn is |Σα| over the run and the straight knot on either
//! side of it (its shoulders), which telescopes to the heading after the corner minus
//! the heading before it: noise on the way does not add up, and a corner that a knot
//! happens to split unevenly is counted whole. A corner chunk covers the chords around
//! its run (the turning time is spent inside one of them) and its length is the driven
//! length through the corner (a Douglas–Peucker simplification of the samples with
//! tolerance `corner_tolerance_m`, so that the chord cutting the corner does not shorten
//! it). Every other chord is a straight chunk (its length, no turn). Each chunk has the
//! time between its end knots.
//!
//! Turns gentler than `straight_rad` per `spacing_m` (curvature radius above about 3 m
//! with the defaults) are not counted: the noise floor.

use super::config::CalibrationConfig;
use super::error::CalibrationError;
use crate::path::distance;

/// The most samples one stretch holds (limit `max_stretch_samples`): an hour of
/// estimates at 25 Hz; a longer mission is split into several stretches.
pub const MAX_STRETCH_SAMPLES: usize = 100_000;

/// A driven position at a time: an estimate or the ground truth, world metres and
/// mission seconds.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Sample {
    pub time_s: f64,
    pub at: [f64; 2],
}

/// The samples of one mission, in time order: a replan starts a new stretch, so no
/// chunk runs across two plans. Non-finite samples are skipped.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Stretch {
    samples: Vec<Sample>,
    skipped: usize,
}

impl Stretch {
    pub fn new() -> Stretch {
        Stretch::default()
    }

    /// A stretch of `samples`; refused beyond [`MAX_STRETCH_SAMPLES`].
    pub fn from_samples(
        samples: impl IntoIterator<Item = Sample>,
    ) -> Result<Stretch, CalibrationError> {
        let mut stretch = Stretch::new();
        for s in samples {
            stretch.push(s)?;
        }
        Ok(stretch)
    }

    /// Adds a sample; a non-finite one is skipped (and counted), one beyond
    /// [`MAX_STRETCH_SAMPLES`] refused.
    pub fn push(&mut self, sample: Sample) -> Result<(), CalibrationError> {
        if !(sample.time_s.is_finite() && sample.at.iter().all(|v| v.is_finite())) {
            self.skipped += 1;
            return Ok(());
        }
        if self.samples.len() >= MAX_STRETCH_SAMPLES {
            return Err(CalibrationError::TooManySamples {
                max: MAX_STRETCH_SAMPLES,
            });
        }
        self.samples.push(sample);
        Ok(())
    }

    pub fn samples(&self) -> &[Sample] {
        &self.samples
    }

    /// Non-finite samples that were skipped.
    pub fn skipped(&self) -> usize {
        self.skipped
    }
}

/// A piece of a stretch: a straight chord or a corner.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Chunk {
    /// Driven length, metres.
    pub distance_m: f64,
    /// Absolute heading change (Eq. 2's θ), radians; 0 for a straight chunk.
    pub turn_rad: f64,
    /// Time from its first knot to its last, seconds (waits included: see `fit`).
    pub duration_s: f64,
    /// The first chunk of a run of samples: it holds whatever happened before the
    /// robot first moved (a wait, a turn toward the path that no chord sees).
    pub leading: bool,
}

/// The chunks of `stretch`, in order. `config` is assumed checked.
pub fn chunks(stretch: &Stretch, config: &CalibrationConfig) -> Vec<Chunk> {
    runs(&stretch.samples, config.max_sample_gap_s)
        .iter()
        .flat_map(|run| run_chunks(run, config))
        .collect()
}

/// Eq. 2's Σd and Σθ of a polyline as it is (a planned path of cell centres, where
/// nothing is noise): the length, and the absolute heading change between consecutive
/// moves (the first move costs no turn, as the planner counts it; repeated points are
/// skipped).
pub fn path_measure(points: &[[f64; 2]]) -> (f64, f64) {
    let (mut d, mut theta, mut heading) = (0.0, 0.0, None::<f64>);
    for pair in points.windows(2) {
        let step = distance(pair[0], pair[1]);
        if !(step.is_finite() && step > 0.0) {
            continue;
        }
        let h = (pair[1][1] - pair[0][1]).atan2(pair[1][0] - pair[0][0]);
        if let Some(prev) = heading {
            theta += wrap(h - prev).abs();
        }
        d += step;
        heading = Some(h);
    }
    (d, theta)
}

/// An angle in [-π, π).
fn wrap(angle: f64) -> f64 {
    use std::f64::consts::{PI, TAU};
    (angle + PI).rem_euclid(TAU) - PI
}

/// Splits samples into runs of strictly increasing time with no gap above `max_gap_s`;
/// a sample at the same time as the previous one is dropped.
fn runs(samples: &[Sample], max_gap_s: f64) -> Vec<Vec<Sample>> {
    let mut out: Vec<Vec<Sample>> = Vec::new();
    let mut run: Vec<Sample> = Vec::new();
    for &s in samples {
        match run.last() {
            Some(last) if s.time_s == last.time_s => continue,
            Some(last) if s.time_s < last.time_s || s.time_s - last.time_s > max_gap_s => {
                out.push(std::mem::take(&mut run));
            }
            _ => {}
        }
        run.push(s);
    }
    out.push(run);
    out.retain(|r| r.len() >= 2);
    out
}

/// A corner: the chords `first..=last` it covers and its turn.
#[derive(Debug, Clone, Copy)]
struct Corner {
    first: usize,
    last: usize,
    turn: f64,
}

fn run_chunks(run: &[Sample], config: &CalibrationConfig) -> Vec<Chunk> {
    // Knots: indices into `run`.
    let mut knots = vec![0usize];
    for (i, s) in run.iter().enumerate().skip(1) {
        if distance(s.at, run[knots[knots.len() - 1]].at) >= config.spacing_m {
            knots.push(i);
        }
    }
    let chords = knots.len().saturating_sub(1);
    if chords == 0 {
        return Vec::new();
    }
    let at = |k: usize| run[knots[k]].at;
    let time = |k: usize| run[knots[k]].time_s;
    let heading: Vec<f64> = (0..chords)
        .map(|c| {
            let (a, b) = (at(c), at(c + 1));
            (b[1] - a[1]).atan2(b[0] - a[0])
        })
        .collect();
    // alpha[j]: the heading change at knot j (1..chords), 0 unused.
    let mut alpha = vec![0.0; chords];
    for j in 1..chords {
        alpha[j] = wrap(heading[j] - heading[j - 1]);
    }
    let turning = |j: usize| alpha[j].abs() >= config.straight_rad;

    let mut corners: Vec<Corner> = Vec::new();
    let mut shoulder_used = vec![false; chords];
    let mut j = 1;
    while j < chords {
        if !turning(j) {
            j += 1;
            continue;
        }
        let (a, sign) = (j, alpha[j].signum());
        while j + 1 < chords && turning(j + 1) && alpha[j + 1].signum() == sign {
            j += 1;
        }
        let b = j;
        let mut sum: f64 = alpha[a..=b].iter().sum();
        if a >= 2 && !turning(a - 1) && !shoulder_used[a - 1] {
            sum += alpha[a - 1];
            shoulder_used[a - 1] = true;
        }
        if b + 1 < chords && !turning(b + 1) {
            sum += alpha[b + 1];
            shoulder_used[b + 1] = true;
        }
        let corner = Corner {
            first: a - 1,
            last: b,
            turn: sum.abs(),
        };
        match corners.last_mut() {
            // Corners sharing a chord (a jog) are one chunk, their turns added.
            Some(prev) if corner.first <= prev.last => {
                prev.last = prev.last.max(corner.last);
                prev.turn += corner.turn;
            }
            _ => corners.push(corner),
        }
        j += 1;
    }

    let mut out = Vec::with_capacity(chords);
    let mut c = 0;
    let mut next_corner = corners.iter().peekable();
    while c < chords {
        match next_corner.peek() {
            Some(corner) if corner.first == c => {
                let samples = &run[knots[corner.first]..=knots[corner.last + 1]];
                out.push(Chunk {
                    distance_m: simplified_length(samples, config.corner_tolerance_m),
                    turn_rad: corner.turn,
                    duration_s: time(corner.last + 1) - time(corner.first),
                    leading: c == 0,
                });
                c = corner.last + 1;
                next_corner.next();
            }
            _ => {
                out.push(Chunk {
                    distance_m: distance(at(c), at(c + 1)),
                    turn_rad: 0.0,
                    duration_s: time(c + 1) - time(c),
                    leading: c == 0,
                });
                c += 1;
            }
        }
    }
    out
}

/// The length of the Douglas–Peucker simplification of `samples` with `tolerance`
/// (distance to the segment, not the line, so a point beyond an end, as at a U-turn,
/// is kept).
fn simplified_length(samples: &[Sample], tolerance: f64) -> f64 {
    let n = samples.len();
    if n < 2 {
        return 0.0;
    }
    let mut keep = vec![false; n];
    keep[0] = true;
    keep[n - 1] = true;
    let mut stack = vec![(0usize, n - 1)];
    while let Some((lo, hi)) = stack.pop() {
        let (a, b) = (samples[lo].at, samples[hi].at);
        let farthest = (lo + 1..hi)
            .map(|i| (i, to_segment(samples[i].at, a, b)))
            .fold(None, |best: Option<(usize, f64)>, (i, d)| match best {
                Some((_, bd)) if bd >= d => best,
                _ => Some((i, d)),
            });
        if let Some((i, d)) = farthest {
            if d > tolerance {
                keep[i] = true;
                stack.push((lo, i));
                stack.push((i, hi));
            }
        }
    }
    let kept: Vec<[f64; 2]> = (0..n).filter(|&i| keep[i]).map(|i| samples[i].at).collect();
    kept.windows(2).map(|w| distance(w[0], w[1])).sum()
}

fn to_segment(p: [f64; 2], a: [f64; 2], b: [f64; 2]) -> f64 {
    crate::path::off_path_m(p, &[a, b])
}

#[cfg(test)]
mod tests {
    use super::*;

    fn line(points: &[[f64; 2]], step_m: f64, speed: f64, pause_s: f64) -> Vec<Sample> {
        // Samples every `step_m` along the polyline at `speed`, waiting `pause_s` at
        // each inner vertex (a turn in place).
        let mut out = vec![Sample {
            time_s: 0.0,
            at: points[0],
        }];
        let mut t = 0.0;
        for (k, pair) in points.windows(2).enumerate() {
            if k > 0 {
                t += pause_s;
                out.push(Sample {
                    time_s: t,
                    at: pair[0],
                });
            }
            let len = distance(pair[0], pair[1]);
            let n = (len / step_m).round().max(1.0) as usize;
            for i in 1..=n {
                let f = i as f64 / n as f64;
                t += len / n as f64 / speed;
                out.push(Sample {
                    time_s: t,
                    at: [
                        pair[0][0] + f * (pair[1][0] - pair[0][0]),
                        pair[0][1] + f * (pair[1][1] - pair[0][1]),
                    ],
                });
            }
        }
        out
    }

    fn stretch(samples: Vec<Sample>) -> Stretch {
        Stretch::from_samples(samples).expect("stretch")
    }

    #[test]
    fn an_l_is_straight_chunks_and_one_corner_counted_whole() {
        let config = CalibrationConfig::default();
        let samples = line(&[[0.0, 0.0], [3.1, 0.0], [3.1, 3.0]], 0.1, 1.0, 2.0);
        let chunks = chunks(&stretch(samples), &config);
        let corners: Vec<_> = chunks.iter().filter(|c| c.turn_rad > 0.0).collect();
        assert_eq!(corners.len(), 1, "{chunks:?}");
        let corner = corners[0];
        assert!((corner.turn_rad - std::f64::consts::FRAC_PI_2).abs() < 1e-9);
        let total: f64 = chunks.iter().map(|c| c.distance_m).sum();
        let time: f64 = chunks.iter().map(|c| c.duration_s).sum();
        // The knots end within a spacing of the end; the corner's length goes round it.
        assert!(
            total > 6.1 - config.spacing_m && total <= 6.1 + 1e-9,
            "{total}"
        );
        assert!(
            (time - (total + 2.0)).abs() < 1e-9,
            "1 m/s plus the 2 s turn: {time}"
        );
        assert!(corner.duration_s > 2.0);
    }

    #[test]
    fn a_u_turn_and_a_jog_are_measured_and_gaps_split_runs() {
        let config = CalibrationConfig::default();
        let u = line(&[[0.0, 0.0], [3.0, 0.0], [0.0, 0.0]], 0.1, 1.0, 1.0);
        let chunks_u = chunks(&stretch(u), &config);
        let turn: f64 = chunks_u.iter().map(|c| c.turn_rad).sum();
        let length: f64 = chunks_u.iter().map(|c| c.distance_m).sum();
        assert!((turn - std::f64::consts::PI).abs() < 1e-6, "{turn}");
        assert!(length > 5.4 && length <= 6.0 + 1e-9, "{length}");

        // A gap in the samples: two runs, nothing measured across it.
        let mut gapped = line(&[[0.0, 0.0], [2.0, 0.0]], 0.1, 1.0, 0.0);
        let later = line(&[[5.0, 0.0], [7.0, 0.0]], 0.1, 1.0, 0.0);
        gapped.extend(later.into_iter().map(|s| Sample {
            time_s: s.time_s + 60.0,
            ..s
        }));
        let chunks_g = chunks(&stretch(gapped), &config);
        let length: f64 = chunks_g.iter().map(|c| c.distance_m).sum();
        assert!(
            length <= 4.0 + 1e-9,
            "the 3 m jump is not driving: {length}"
        );
        assert!(chunks_g.iter().all(|c| c.duration_s < 5.0));
    }

    #[test]
    fn noise_on_a_straight_line_adds_no_turn() {
        let config = CalibrationConfig::default();
        let mut rng_state = 12345u64;
        let mut noise = || {
            // A small deterministic LCG: uniform in ±0.01 m.
            rng_state = rng_state.wrapping_mul(6364136223846793005).wrapping_add(1);
            ((rng_state >> 11) as f64 / (1u64 << 53) as f64 - 0.5) * 0.02
        };
        let samples: Vec<Sample> = (0..200)
            .map(|i| Sample {
                time_s: f64::from(i) * 0.4,
                at: [f64::from(i) * 0.2 + noise(), noise()],
            })
            .collect();
        let chunks = chunks(&stretch(samples.clone()), &config);
        let turn: f64 = chunks.iter().map(|c| c.turn_rad).sum();
        assert!(turn < 0.05, "{turn} rad over 40 m of a straight line");
        // Summing every sample's heading change instead would count the noise.
        let naive = path_measure(&samples.iter().map(|s| s.at).collect::<Vec<_>>()).1;
        assert!(naive > 2.0, "{naive}");
    }

    #[test]
    fn a_planned_path_is_measured_as_eq_2_counts_it() {
        let (d, theta) =
            path_measure(&[[0.0, 0.0], [0.2, 0.0], [0.4, 0.2], [0.4, 0.2], [0.4, 0.4]]);
        assert!((d - (0.4 + 0.2 * std::f64::consts::SQRT_2)).abs() < 1e-12);
        assert!(
            (theta - std::f64::consts::FRAC_PI_2).abs() < 1e-12,
            "two 45° turns"
        );
        assert_eq!(path_measure(&[[1.0, 1.0]]), (0.0, 0.0));
    }

    #[test]
    fn bad_samples_are_skipped_and_a_stretch_is_bounded() {
        let mut s = Stretch::new();
        s.push(Sample {
            time_s: f64::NAN,
            at: [0.0, 0.0],
        })
        .expect("skipped");
        s.push(Sample {
            time_s: 0.0,
            at: [f64::INFINITY, 0.0],
        })
        .expect("skipped");
        assert_eq!((s.samples().len(), s.skipped()), (0, 2));
        let many = (0..=MAX_STRETCH_SAMPLES).map(|i| Sample {
            time_s: i as f64,
            at: [0.0, 0.0],
        });
        let err = Stretch::from_samples(many).expect_err("too many");
        assert!(err.to_string().contains("max_stretch_samples"), "{err}");
    }
}
