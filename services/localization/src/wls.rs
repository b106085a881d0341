//! The weighted least-squares position estimate from TOA ranges (paper 002 §2.1: "a robot
//! can estimate its location according to a weighted least squares localizer"), its
//! covariance taken as the CRB at the estimate (paper 002 §2.2).
//!
//! Minimises Σ_i w_i (d̂_i − ‖p − a_i‖)² by Gauss–Newton with a backtracking line search,
//! started from the prior (the last estimate) or, without one, from the closed-form
//! linearised solution: subtracting the first range equation ‖p − a_0‖² = d̂_0² from the
//! others, ‖p − a_i‖² = d̂_i², cancels ‖p‖² and leaves the linear system
//! 2 (a_i − a_0)ᵀ p = d̂_0² − d̂_i² + ‖a_i‖² − ‖a_0‖², solved by least squares (in
//! coordinates centred on the anchors, for conditioning).
//!
//! **Weights**: w_i = 1/σ²(d_i(p̂)), the noise variance at the *predicted* range from the
//! current iterate, re-evaluated every iteration (iteratively reweighted). The predicted
//! range is noise-free given p̂, so the weight is independent of that range's own noise
//! (weighting by the measured range would down-weight ranges that happen to come out
//! long, a bias), and at convergence the normal matrix is the FIM without the
//! variance-derivative term, so the estimate attains the CRB at high SNR. The closed-form
//! start, having no iterate, is unweighted.
//!
//! **Two anchors, or anchors in one line** (a site's `sensing.fix_anchors: 2`; the default
//! is 3 and the papers' worlds keep it): the ranges fix the position up to its mirror
//! image in the anchors' line. With a prior (the robot's last fix) Gauss–Newton started
//! there settles on the nearer of the two, and the estimate is a fix when the mirror
//! image is clearly farther from the prior: at least [`MIRROR_MARGIN`] times as far.
//! Near the line the two points merge, the margin fails and the estimate is degraded
//! (the FIM, nearly singular there, would give a large PEB anyway). Without a prior
//! nothing tells the two apart: degraded.

use nalgebra::{Matrix2, Vector2};

use crate::error::LocalizationError;
use crate::fim::{bound_from_fim, fim_from, FimOptions};
use crate::model::{RangingModel, MIN_DISTANCE_M};

/// The most ranges one estimate takes.
pub const MAX_RANGES: usize = 4096;

/// A fix from anchors in one line (module doc) holds when the mirror image of the
/// solution in that line is at least this many times as far from the prior as the
/// solution: with the prior e metres off, the robot at h metres from the line, about
/// e < 2h/3.
pub const MIRROR_MARGIN: f64 = 2.0;

/// One measured range d̂ to an anchor of the model (paper 002 §2.1).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Range {
    /// Index of the anchor in the model.
    pub anchor: usize,
    /// Measured range, metres (may be slightly negative very close to an anchor).
    pub range_m: f64,
}

/// How the estimator runs.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct WlsOptions {
    /// Gauss–Newton iterations at most before the estimate counts as not converged.
    pub max_iterations: usize,
    /// Converged when a step is shorter than this, metres.
    pub tolerance_m: f64,
    /// A range is usable when d̂ ≤ s_r + `gate_slack_sigmas` · σ(s_r). Paper 002 §2.1
    /// gates by d̂ ≤ s_r, but roam-sim's default gate is the *true* distance, so a heard
    /// anchor can report a range a little beyond s_r; dropping those would bias the
    /// estimate. 3σ keeps 99.9 % of them; 0 is the paper's literal gate.
    pub gate_slack_sigmas: f64,
    /// The usable anchors are collinear when the spread across their best-fit line is at
    /// most this fraction of the spread along it (√(λ_min/λ_max) of their scatter).
    pub min_anchor_spread: f64,
    /// How the covariance (the CRB at the estimate) is formed.
    pub fim: FimOptions,
}

impl Default for WlsOptions {
    fn default() -> Self {
        WlsOptions {
            max_iterations: 25,
            tolerance_m: 1e-7,
            gate_slack_sigmas: 3.0,
            min_anchor_spread: 1e-3,
            fim: FimOptions::default(),
        }
    }
}

/// Why an estimate is degraded.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Degraded {
    /// Fewer than three distinct anchors gave a usable range (a 2-D fix from fewer is
    /// ambiguous: two circles meet in two points).
    TooFewAnchors { usable: usize },
    /// The usable anchors lie on one line (the fix is ambiguous by reflection in it), and
    /// the model wants three anchors or there is no prior to tell the two points apart.
    CollinearAnchors,
    /// Two anchors (or anchors in one line) and a prior, but the solution's mirror image
    /// is not clearly farther from the prior ([`MIRROR_MARGIN`]): the robot is near the
    /// anchors' line, or its prior is old.
    Ambiguous,
    /// Gauss–Newton did not settle within the iteration limit, or left finite numbers.
    NotConverged,
    /// The normal matrix or the FIM at the estimate is singular or ill-conditioned.
    SingularFim,
}

/// A position estimate with its uncertainty (paper 002 §2.1–2.2).
#[derive(Debug, Clone, PartialEq)]
pub struct Estimate {
    /// The estimated position, world metres. When degraded: the prior if there was one,
    /// otherwise the centroid of the usable anchors, otherwise of all anchors, otherwise
    /// the origin; never NaN.
    pub position: [f64; 2],
    /// The CRB at the estimate over the anchors used, m² (paper 002 §2.2). When degraded:
    /// +∞ on the diagonal, 0 off it (the position does not come from the ranges).
    pub covariance: Matrix2<f64>,
    /// √tr(covariance), metres; +∞ when degraded.
    pub peb: f64,
    /// Indices of the distinct anchors whose ranges were usable, ascending.
    pub anchors_used: Vec<usize>,
    /// Whether the estimate is not a WLS fix (see `reason`).
    pub degraded: bool,
    /// Why it is degraded; `None` when it is not.
    pub reason: Option<Degraded>,
    /// Gauss–Newton iterations run.
    pub iterations: usize,
}

/// The WLS position estimate from `ranges` (paper 002 §2.1), iterated from `prior` or
/// from the closed-form linearised start when `prior` is `None`.
///
/// Refuses (an error) a range naming an unknown anchor, a non-finite range or prior, or
/// more than [`MAX_RANGES`] ranges. Degenerate data (fewer than three usable anchors,
/// collinear anchors, non-convergence) is not an error: the estimate keeps the prior and
/// is flagged degraded.
pub fn estimate(
    model: &RangingModel,
    ranges: &[Range],
    prior: Option<[f64; 2]>,
    options: &WlsOptions,
) -> Result<Estimate, LocalizationError> {
    if ranges.len() > MAX_RANGES {
        return Err(LocalizationError::TooManyRanges {
            count: ranges.len(),
            max: MAX_RANGES,
        });
    }
    let anchors = model.anchors();
    for r in ranges {
        if r.anchor >= anchors.len() {
            return Err(LocalizationError::UnknownAnchor {
                index: r.anchor,
                count: anchors.len(),
            });
        }
        if !r.range_m.is_finite() {
            return Err(LocalizationError::BadRange {
                index: r.anchor,
                value: r.range_m,
            });
        }
    }
    if let Some(p) = prior {
        if !(p[0].is_finite() && p[1].is_finite()) {
            return Err(LocalizationError::BadPoint { at: p });
        }
    }

    let gate = model.sensing_range_m()
        + options.gate_slack_sigmas.max(0.0) * model.noise().sigma(model.sensing_range_m());
    let usable: Vec<(Vector2<f64>, f64)> = ranges
        .iter()
        .filter(|r| r.range_m <= gate)
        .map(|r| (anchors[r.anchor], r.range_m))
        .collect();
    let mut used: Vec<usize> = ranges
        .iter()
        .filter(|r| r.range_m <= gate)
        .map(|r| r.anchor)
        .collect();
    used.sort_unstable();
    used.dedup();

    let fail = |reason: Degraded, iterations: usize, used: Vec<usize>| {
        let position = prior
            .or_else(|| centroid(usable.iter().map(|u| u.0)))
            .or_else(|| centroid(anchors.iter().copied()))
            .unwrap_or([0.0, 0.0]);
        Estimate {
            position,
            covariance: Matrix2::new(f64::INFINITY, 0.0, 0.0, f64::INFINITY),
            peb: f64::INFINITY,
            anchors_used: used,
            degraded: true,
            reason: Some(reason),
            iterations,
        }
    };

    if used.len() < model.fix_anchors() {
        return Ok(fail(
            Degraded::TooFewAnchors { usable: used.len() },
            0,
            used,
        ));
    }
    // Anchors in one line: a fix only from a prior, checked against the mirror image.
    let in_line = spread(usable.iter().map(|u| u.0)) <= options.min_anchor_spread;
    let mirror_line = match (in_line, prior) {
        (false, _) => None,
        (true, Some(_)) if model.fix_anchors() <= 2 => match line_of(&usable) {
            Some(line) => Some(line),
            None => return Ok(fail(Degraded::CollinearAnchors, 0, used)),
        },
        (true, _) => return Ok(fail(Degraded::CollinearAnchors, 0, used)),
    };
    let start = match prior {
        Some(p) => Vector2::new(p[0], p[1]),
        None => match linearised_start(&usable) {
            Some(p) => p,
            None => return Ok(fail(Degraded::CollinearAnchors, 0, used)),
        },
    };

    let (x, iterations) = match gauss_newton(model, &usable, start, options) {
        Ok(done) => done,
        Err((reason, iterations)) => return Ok(fail(reason, iterations, used)),
    };
    if let (Some((point, direction)), Some(p)) = (mirror_line, prior) {
        let p = Vector2::new(p[0], p[1]);
        let offset = x - point;
        let mirror = point + direction * (2.0 * offset.dot(&direction)) - offset;
        if (mirror - p).norm() < MIRROR_MARGIN * (x - p).norm() {
            return Ok(fail(Degraded::Ambiguous, iterations, used));
        }
    }
    let (f, n) = fim_from(model, usable.iter().map(|u| u.0), x, &options.fim);
    let b = bound_from_fim(f, n, model.fix_anchors(), &options.fim);
    if b.degraded {
        return Ok(fail(Degraded::SingularFim, iterations, used));
    }
    Ok(Estimate {
        position: [x[0], x[1]],
        covariance: b.crb,
        peb: b.peb,
        anchors_used: used,
        degraded: false,
        reason: None,
        iterations,
    })
}

/// Gauss–Newton on the WLS cost with weights 1/σ²(predicted range) (module doc), halving
/// each step until the cost (at the iteration's weights) does not rise. Returns the
/// converged position and the iterations run, or why it failed.
fn gauss_newton(
    model: &RangingModel,
    usable: &[(Vector2<f64>, f64)],
    start: Vector2<f64>,
    options: &WlsOptions,
) -> Result<(Vector2<f64>, usize), (Degraded, usize)> {
    let mut x = start;
    for it in 1..=options.max_iterations {
        let mut h = Matrix2::zeros();
        let mut g = Vector2::zeros();
        let mut cost = 0.0;
        for &(a, r) in usable {
            let diff = x - a;
            let d = diff.norm();
            let w = 1.0 / model.variance(d);
            let res = r - d;
            cost += w * res * res;
            if d < MIN_DISTANCE_M {
                continue;
            }
            let u = diff / d;
            h += u * u.transpose() * w;
            g += u * (w * res);
        }
        let (a, b, c) = (h[(0, 0)], h[(0, 1)], h[(1, 1)]);
        let tr = a + c;
        let det = a * c - b * b;
        let lambda_max = 0.5 * tr + (0.5 * (a - c)).hypot(b);
        if !(tr.is_finite() && tr > 0.0 && det / (lambda_max * lambda_max) > options.fim.min_rcond)
        {
            return Err((Degraded::SingularFim, it));
        }
        let delta = Matrix2::new(c, -b, -b, a) * g / det;
        if !(delta[0].is_finite() && delta[1].is_finite()) {
            return Err((Degraded::NotConverged, it));
        }
        if delta.norm() < options.tolerance_m {
            return Ok((x + delta, it));
        }
        let mut t = 1.0;
        let mut accepted = false;
        for _ in 0..40 {
            let candidate = x + delta * t;
            let new_cost: f64 = usable
                .iter()
                .map(|&(a, r)| {
                    let dx = candidate - a;
                    let w = 1.0 / model.variance((x - a).norm());
                    let res = r - dx.norm();
                    w * res * res
                })
                .sum();
            if new_cost <= cost {
                x = candidate;
                accepted = true;
                break;
            }
            t *= 0.5;
            if delta.norm() * t < options.tolerance_m {
                break;
            }
        }
        if !accepted || delta.norm() * t < options.tolerance_m {
            // No step along the Gauss–Newton direction lowers the cost: a minimum.
            return Ok((x, it));
        }
    }
    Err((Degraded::NotConverged, options.max_iterations))
}

/// The closed-form linearised start (module doc), in coordinates centred on the anchors'
/// centroid; `None` when the linear system is singular (collinear anchors).
fn linearised_start(usable: &[(Vector2<f64>, f64)]) -> Option<Vector2<f64>> {
    let c = centroid(usable.iter().map(|u| u.0))?;
    let c = Vector2::new(c[0], c[1]);
    let (a0, r0) = usable.first().map(|&(a, r)| (a - c, r))?;
    let mut m = Matrix2::zeros();
    let mut rhs = Vector2::zeros();
    for &(a, r) in &usable[1..] {
        let ai = a - c;
        let row = (ai - a0) * 2.0;
        let y = r0 * r0 - r * r + ai.norm_squared() - a0.norm_squared();
        m += row * row.transpose();
        rhs += row * y;
    }
    let (a, b, d) = (m[(0, 0)], m[(0, 1)], m[(1, 1)]);
    let det = a * d - b * b;
    let tr = a + d;
    if !(tr > 0.0 && det > 1e-12 * tr * tr) {
        return None;
    }
    let q = Matrix2::new(d, -b, -b, a) * rhs / det;
    let p = q + c;
    (p[0].is_finite() && p[1].is_finite()).then_some(p)
}

/// The best-fit line of the anchors: a point on it (their centroid) and its unit
/// direction (the scatter's principal axis); `None` when they are all one point.
fn line_of(usable: &[(Vector2<f64>, f64)]) -> Option<(Vector2<f64>, Vector2<f64>)> {
    let (c, s) = scatter(usable.iter().map(|u| u.0))?;
    let (a, b, d) = (s[(0, 0)], s[(0, 1)], s[(1, 1)]);
    let lambda_max = largest_eigenvalue(&s);
    // An eigenvector of the largest eigenvalue: (b, λ − a) or (λ − d, b), the longer.
    let (u, v) = (
        Vector2::new(b, lambda_max - a),
        Vector2::new(lambda_max - d, b),
    );
    let direction = if u.norm() >= v.norm() { u } else { v };
    let norm = direction.norm();
    (norm.is_finite() && norm > 0.0).then(|| (c, direction / norm))
}

/// The points' centroid and scatter matrix Σ (p − c)(p − c)ᵀ; `None` for no points.
fn scatter(
    points: impl Iterator<Item = Vector2<f64>> + Clone,
) -> Option<(Vector2<f64>, Matrix2<f64>)> {
    let c = centroid(points.clone())?;
    let c = Vector2::new(c[0], c[1]);
    let s = points.fold(Matrix2::zeros(), |s, p| {
        let q = p - c;
        s + q * q.transpose()
    });
    Some((c, s))
}

/// The larger eigenvalue of a symmetric 2 × 2 matrix, in closed form.
fn largest_eigenvalue(s: &Matrix2<f64>) -> f64 {
    let (a, b, d) = (s[(0, 0)], s[(0, 1)], s[(1, 1)]);
    0.5 * (a + d) + (0.5 * (a - d)).hypot(b)
}

/// The mean of the points, or `None` for none.
fn centroid(points: impl Iterator<Item = Vector2<f64>>) -> Option<[f64; 2]> {
    let (sum, n) = points.fold((Vector2::zeros(), 0usize), |(s, n), p| (s + p, n + 1));
    (n > 0).then(|| {
        let m = sum / n as f64;
        [m[0], m[1]]
    })
}

/// √(λ_min/λ_max) of the points' scatter matrix: 0 for points on one line, 1 for points
/// spread alike in every direction; 0 for fewer than two distinct points.
fn spread(points: impl Iterator<Item = Vector2<f64>> + Clone) -> f64 {
    let Some((_, s)) = scatter(points) else {
        return 0.0;
    };
    let lambda_max = largest_eigenvalue(&s);
    if lambda_max.is_nan() || lambda_max <= 0.0 {
        return 0.0;
    }
    let lambda_min = (s[(0, 0)] * s[(1, 1)] - s[(0, 1)] * s[(0, 1)]) / lambda_max;
    (lambda_min.max(0.0) / lambda_max).sqrt()
}
