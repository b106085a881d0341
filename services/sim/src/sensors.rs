//! A robot's TOA range sensor (paper 002 §2.1) and what its readings look like.

use rand::RngCore;
use roam_world::scenario::{RangeGate, SensingSpec};
use serde::Serialize;

use crate::world::Anchor;
use roam_world::noise::ToaNoise;
use roam_world::observation::Observation;

/// One TOA range: `d̂ = d + n` to one anchor.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Range {
    /// The anchor's index in `Sim::anchors()` (its name and position are there).
    pub anchor: usize,
    /// The measured range d̂, metres (may exceed the sensing range under
    /// `RangeGate::TrueDistance`, and may be slightly negative next to an anchor).
    pub range_m: f64,
}

/// The ranges a robot at `at` measures to `anchors`.
///
/// One noise draw per anchor, in anchor order, every step, whether the anchor is in
/// range or not: the robot's stream then advances the same way wherever it goes, so
/// the noise on a given step does not depend on the path taken. Which ranges are kept
/// follows `spec.range_gate`: by true distance `d ≤ s_r` (default) or by measured
/// distance `d̂ ≤ s_r` (paper 002 §2.1 writes both).
pub fn ranges(
    at: [f64; 2],
    anchors: &[Anchor],
    spec: &SensingSpec,
    rng: &mut impl RngCore,
) -> Vec<Range> {
    let noise = ToaNoise::from_spec(spec);
    let mut out = Vec::new();
    for (anchor, a) in anchors.iter().enumerate() {
        let d = (a.at[0] - at[0]).hypot(a.at[1] - at[1]);
        let range_m = noise.measure(d, rng);
        let gate = match spec.range_gate {
            RangeGate::TrueDistance => d,
            RangeGate::Measured => range_m,
        };
        if gate <= spec.range_m {
            out.push(Range { anchor, range_m });
        }
    }
    out
}

/// Everything a robot reports after a step.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Readings {
    /// The ground-truth position, world metres: for evaluation only, never for the
    /// robot's own estimate.
    pub truth: [f64; 2],
    /// The ground-truth heading, radians counter-clockwise from +x in [-π, π), for a
    /// unicycle (roam's addition); `None` for paper 002's point robot, which has none.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub heading_rad: Option<f64>,
    /// TOA ranges to the anchors within the sensing range, in anchor order.
    pub ranges: Vec<Range>,
    /// The local grid within the observation radius, with line of sight; `None` when
    /// the radius is 0.
    pub observation: Option<Observation>,
}
