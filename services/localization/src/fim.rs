//! The Fisher information matrix of a 2-D position from TOA ranges, the Cramér–Rao bound
//! CRB = F⁻¹ and the position error bound PEB = √tr(F⁻¹) (paper 002 §2.2, for one robot:
//! the non-collaborative FIM is block diagonal, so each robot has its own 2 × 2 block).
//!
//! For a range d_i = ‖p − a_i‖ with unit vector u_i = (p − a_i)/d_i and distance-dependent
//! Gaussian noise of variance v_i(d) (paper 002 §2.1),
//!
//! ```text
//! F(p) = Σ_i u_i u_iᵀ · (1/v_i + v_i′² / (2 v_i²))
//! ```
//!
//! over the anchors in sensing range (d_i ≤ s_r). The second term is the information the
//! *variance* carries about the distance (paper 002 leaves open whether it counts; see
//! [`FimOptions::variance_derivative`]).

use nalgebra::{Matrix2, Vector2};

use crate::model::{RangingModel, MIN_DISTANCE_M};

/// The default reciprocal condition number below which a FIM counts as singular.
pub const DEFAULT_MIN_RCOND: f64 = 1e-9;

/// The fewest anchors in range the estimator fixes a position from, unless the scenario
/// says otherwise (`sensing.fix_anchors`, [`RangingModel::fix_anchors`]): two range
/// circles meet in two points, so two anchors leave the position ambiguous without a
/// prior. The bound follows the estimator (one rule): with fewer anchors than the model's
/// minimum the PEB is +∞ and the bound degraded, although the FIM of two non-collinear
/// anchors is invertible. Paper 002 §2.2 does not say; with the bound finite where the
/// estimator has no fix, the IS field, the `peb` layer and the planner's W_loc cost
/// would call localizable a place where the robot had no fix, and the controller's
/// guard would hold it there.
pub const MIN_FIX_ANCHORS: usize = roam_world::scenario::DEFAULT_FIX_ANCHORS;

/// How the FIM is formed and when it counts as singular.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FimOptions {
    /// Include the variance-derivative term v′²/(2v²) of each range's information
    /// (paper 002 §2.2 with §2.1's distance-dependent noise; the paper does not say).
    /// Default **on**: it is part of the exact Fisher information of a Gaussian whose
    /// variance depends on the unknown position, so the bound is the true CRB. It is zero
    /// up to d0 and, at paper 002's parameters (σ = 0.1 m, d0 = 15 m, K = 2, s_r = 30 m),
    /// at most about 1e-4 of the 1/v term, so the choice matters only for large σ or K.
    /// The WLS estimator does not use the information in the variance, so with this on
    /// the bound can be (very slightly) below what WLS attains.
    pub variance_derivative: bool,
    /// A FIM whose reciprocal condition number λ_min/λ_max is not above this is singular
    /// (fewer than two anchors in range, or all in line with the point): its PEB is +∞
    /// and the result is degraded.
    pub min_rcond: f64,
}

impl Default for FimOptions {
    fn default() -> Self {
        FimOptions {
            variance_derivative: true,
            min_rcond: DEFAULT_MIN_RCOND,
        }
    }
}

/// The FIM, CRB and PEB at one point (paper 002 §2.2).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Bound {
    /// The Fisher information matrix F, 1/m².
    pub fim: Matrix2<f64>,
    /// The Cramér–Rao bound F⁻¹, m². When degraded: +∞ on the diagonal and 0 off it
    /// (unbounded in every direction; never NaN).
    pub crb: Matrix2<f64>,
    /// The position error bound √tr(F⁻¹), metres; +∞ when degraded.
    pub peb: f64,
    /// How many anchors contributed (in sensing range and not on the point).
    pub anchors_used: usize,
    /// The FIM is singular or ill-conditioned (see [`FimOptions::min_rcond`]).
    pub degraded: bool,
}

/// The FIM at `p` from every anchor of `model` within the sensing range (paper 002 §2.2).
/// Returns the matrix and the number of anchors that contributed. A non-finite `p` hears
/// no anchor and gives the zero matrix.
pub fn fim(model: &RangingModel, p: [f64; 2], options: &FimOptions) -> (Matrix2<f64>, usize) {
    let p = Vector2::new(p[0], p[1]);
    fim_from(
        model,
        model.anchors().iter().copied().filter(|a| {
            let d = (p - a).norm();
            model.in_range(d)
        }),
        p,
        options,
    )
}

/// The FIM at `p` from the given anchor positions, all counted whatever their distance
/// (the estimator uses it over the anchors whose ranges it used; paper 002 §2.2). Anchors
/// at a non-finite distance or closer than [`MIN_DISTANCE_M`] contribute nothing.
pub fn fim_from(
    model: &RangingModel,
    anchors: impl Iterator<Item = Vector2<f64>>,
    p: Vector2<f64>,
    options: &FimOptions,
) -> (Matrix2<f64>, usize) {
    let mut f = Matrix2::zeros();
    let mut used = 0;
    for a in anchors {
        let diff = p - a;
        let d = diff.norm();
        if !(d.is_finite() && d >= MIN_DISTANCE_M) {
            continue;
        }
        let u = diff / d;
        let w = model.range_information(d, options.variance_derivative);
        if !w.is_finite() {
            continue;
        }
        f += u * u.transpose() * w;
        used += 1;
    }
    (f, used)
}

/// The CRB and PEB of a FIM (paper 002 §2.2: CRB = F⁻¹, PEB = √tr(F⁻¹)), degraded when
/// fewer than `fix_anchors` anchors contributed ([`RangingModel::fix_anchors`]), when F
/// is singular or ill-conditioned (λ_min/λ_max ≤ `min_rcond`, computed in closed form
/// for the symmetric 2 × 2 matrix) or anything is not finite.
pub fn bound_from_fim(
    f: Matrix2<f64>,
    anchors_used: usize,
    fix_anchors: usize,
    options: &FimOptions,
) -> Bound {
    let degraded = Bound {
        fim: f,
        crb: Matrix2::new(f64::INFINITY, 0.0, 0.0, f64::INFINITY),
        peb: f64::INFINITY,
        anchors_used,
        degraded: true,
    };
    if anchors_used < fix_anchors {
        return degraded;
    }
    let (a, b, c) = (f[(0, 0)], 0.5 * (f[(0, 1)] + f[(1, 0)]), f[(1, 1)]);
    let tr = a + c;
    if !(tr.is_finite() && tr > 0.0 && b.is_finite()) {
        return degraded;
    }
    let lambda_max = 0.5 * tr + (0.5 * (a - c)).hypot(b);
    let det = a * c - b * b;
    let rcond = det / (lambda_max * lambda_max);
    if rcond.is_nan() || rcond <= options.min_rcond {
        return degraded;
    }
    let crb = Matrix2::new(c, -b, -b, a) / det;
    let peb = (tr / det).sqrt();
    if !(peb.is_finite() && crb.iter().all(|x| x.is_finite())) {
        return degraded;
    }
    Bound {
        fim: f,
        crb,
        peb,
        anchors_used,
        degraded: false,
    }
}

/// The FIM, CRB and PEB at `p` over the anchors of `model` in sensing range (paper 002
/// §2.2). Never panics, never NaN: a singular FIM gives PEB = +∞ and `degraded`.
pub fn bound(model: &RangingModel, p: [f64; 2], options: &FimOptions) -> Bound {
    let (f, used) = fim(model, p, options);
    bound_from_fim(f, used, model.fix_anchors(), options)
}
