//! The PEB and CRB (paper 002 §2.2) at a list of points and over a grid region for an
//! anchor constellation, and the gradient of the PEB (the information-seeking force of
//! paper 002 §3 is its negative).
//!
//! Grids are row-major (`y · width + x`), row 0 at the region's origin, each value taken
//! at its cell's centre `origin + (i + 0.5) · resolution` (the map server's convention),
//! as `f32` for a map layer. Where the FIM is singular (fewer than two anchors in range,
//! or all in line with the point) the PEB and the CRB's diagonal are `f32::INFINITY`
//! (and the CRB's off-diagonal 0), never NaN; an encoder that cannot carry ∞ must map it.

use nalgebra::Matrix2;

use crate::error::LocalizationError;
use crate::fim::{bound, bound_from_fim, Bound, FimOptions};
use crate::model::{RangingModel, MIN_DISTANCE_M};

/// The most cells one field holds (2000 × 2000).
pub const MAX_FIELD_CELLS: usize = 4_000_000;

/// The most points one point query holds.
pub const MAX_POINTS: usize = 1_000_000;

/// The default step h of the PEB's central differences, metres. The PEB varies on the
/// scale of the anchor distances (metres), so the O(h²) truncation error is about 1e-3
/// of the slope's scale and rounding (ε·PEB/h ≈ 1e-15) is nil; 0.05 m is a quarter of
/// paper 002's step μ = 0.2 m, so the slope describes what the robot's next step reaches.
/// Differences rather than the analytic gradient: the PEB jumps at d0 (the variance's
/// step) and at s_r (an anchor drops out), where no gradient exists anyway, and the
/// differences reuse the one tested PEB code path.
pub const DEFAULT_GRADIENT_STEP_M: f64 = 0.05;

/// A grid region: `width × height` square cells of `resolution_m` metres, the lower-left
/// corner of cell (0, 0) at `origin` (world metres).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GridRegion {
    pub origin: [f64; 2],
    pub resolution_m: f64,
    pub width: usize,
    pub height: usize,
}

impl GridRegion {
    /// The centre of cell (x, y), world metres.
    pub fn cell_center(&self, x: usize, y: usize) -> [f64; 2] {
        [
            self.origin[0] + (x as f64 + 0.5) * self.resolution_m,
            self.origin[1] + (y as f64 + 0.5) * self.resolution_m,
        ]
    }

    fn check(&self) -> Result<(), LocalizationError> {
        let bad = |reason: String| LocalizationError::BadRegion {
            width: self.width,
            height: self.height,
            reason,
        };
        if !(self.origin[0].is_finite() && self.origin[1].is_finite()) {
            return Err(bad(format!(
                "its origin ({}, {}) must be finite metres",
                self.origin[0], self.origin[1]
            )));
        }
        if !(self.resolution_m.is_finite() && self.resolution_m > 0.0) {
            return Err(bad(format!(
                "its resolution {} must be a positive number of metres",
                self.resolution_m
            )));
        }
        match self.width.checked_mul(self.height) {
            Some(n) if n <= MAX_FIELD_CELLS => Ok(()),
            _ => Err(bad(format!(
                "at most {MAX_FIELD_CELLS} cells are allowed: coarsen the resolution or split the region"
            ))),
        }
    }
}

/// A PEB layer (paper 002 §2.2), metres per cell.
#[derive(Debug, Clone, PartialEq)]
pub struct PebField {
    pub region: GridRegion,
    /// √tr(CRB) at each cell centre; +∞ where the FIM is singular.
    pub peb: Vec<f32>,
}

/// PEB and CRB layers (paper 002 §2.2): the CRB's three distinct entries, m².
#[derive(Debug, Clone, PartialEq)]
pub struct CrbField {
    pub region: GridRegion,
    pub peb: Vec<f32>,
    pub crb_xx: Vec<f32>,
    pub crb_xy: Vec<f32>,
    pub crb_yy: Vec<f32>,
}

/// The FIM, CRB and PEB at each point (paper 002 §2.2), over the anchors in range.
pub fn bounds_at(
    model: &RangingModel,
    points: &[[f64; 2]],
    options: &FimOptions,
) -> Result<Vec<Bound>, LocalizationError> {
    if points.len() > MAX_POINTS {
        return Err(LocalizationError::TooManyPoints {
            count: points.len(),
            max: MAX_POINTS,
        });
    }
    if let Some(p) = points
        .iter()
        .find(|p| !(p[0].is_finite() && p[1].is_finite()))
    {
        return Err(LocalizationError::BadPoint { at: *p });
    }
    Ok(points.iter().map(|&p| bound(model, p, options)).collect())
}

/// The PEB over a grid region (paper 002 §2.2): the entry point for a PEB map layer.
pub fn peb_field(
    model: &RangingModel,
    region: &GridRegion,
    options: &FimOptions,
) -> Result<PebField, LocalizationError> {
    region.check()?;
    let kernel = Kernel::new(model, options);
    let mut peb = Vec::with_capacity(region.width * region.height);
    for y in 0..region.height {
        for x in 0..region.width {
            let b = kernel.bound_at(region.cell_center(x, y), options);
            peb.push(b.peb as f32);
        }
    }
    Ok(PebField {
        region: *region,
        peb,
    })
}

/// The PEB and CRB over a grid region (paper 002 §2.2).
pub fn crb_field(
    model: &RangingModel,
    region: &GridRegion,
    options: &FimOptions,
) -> Result<CrbField, LocalizationError> {
    region.check()?;
    let kernel = Kernel::new(model, options);
    let n = region.width * region.height;
    let mut out = CrbField {
        region: *region,
        peb: Vec::with_capacity(n),
        crb_xx: Vec::with_capacity(n),
        crb_xy: Vec::with_capacity(n),
        crb_yy: Vec::with_capacity(n),
    };
    for y in 0..region.height {
        for x in 0..region.width {
            let b = kernel.bound_at(region.cell_center(x, y), options);
            out.peb.push(b.peb as f32);
            out.crb_xx.push(b.crb[(0, 0)] as f32);
            out.crb_xy.push(b.crb[(0, 1)] as f32);
            out.crb_yy.push(b.crb[(1, 1)] as f32);
        }
    }
    Ok(out)
}

/// The gradient of the PEB at `p` (paper 002 §2.2's PEB; §3's information-seeking force
/// is its negative), by central differences with step `step_m` (see
/// [`DEFAULT_GRADIENT_STEP_M`]). `None` where the PEB at `p` is infinite. Where one
/// neighbour along an axis is infinite (a coverage edge within `step_m`), that component
/// is the one-sided difference towards the finite neighbour; where both are, it is 0.
pub fn peb_gradient(
    model: &RangingModel,
    p: [f64; 2],
    step_m: f64,
    options: &FimOptions,
) -> Result<Option<[f64; 2]>, LocalizationError> {
    if !(p[0].is_finite() && p[1].is_finite()) {
        return Err(LocalizationError::BadPoint { at: p });
    }
    if !(step_m.is_finite() && step_m > 0.0) {
        return Err(LocalizationError::BadParameter {
            name: "gradient step",
            value: step_m,
            expected: "a positive finite number of metres",
        });
    }
    let f0 = bound(model, p, options).peb;
    if !f0.is_finite() {
        return Ok(None);
    }
    let mut g = [0.0; 2];
    for (axis, gi) in g.iter_mut().enumerate() {
        let mut plus = p;
        plus[axis] += step_m;
        let mut minus = p;
        minus[axis] -= step_m;
        let fp = bound(model, plus, options).peb;
        let fm = bound(model, minus, options).peb;
        *gi = match (fp.is_finite(), fm.is_finite()) {
            (true, true) => (fp - fm) / (2.0 * step_m),
            (true, false) => (fp - f0) / step_m,
            (false, true) => (f0 - fm) / step_m,
            (false, false) => 0.0,
        };
    }
    Ok(Some(g))
}

/// The FIM of paper 002 §2.2 specialised for many points: the noise constants are
/// precomputed once, u uᵀ is formed from squared offsets without a square root, and
/// (d/d0)^K is (d²/d0²) for the common K = 2 (otherwise one `powf`); no allocation per
/// point. Agrees with [`crate::fim::fim`] to rounding.
#[derive(Debug)]
struct Kernel {
    anchors: Vec<[f64; 2]>,
    range2: f64,
    d0_2: f64,
    inv_s2: f64,
    half_k: f64,
    k2: f64,
    k_is_2: bool,
    derivative: bool,
    fix_anchors: usize,
}

impl Kernel {
    fn new(model: &RangingModel, options: &FimOptions) -> Kernel {
        let n = model.noise();
        Kernel {
            anchors: model.anchors().iter().map(|a| [a[0], a[1]]).collect(),
            range2: model.sensing_range_m() * model.sensing_range_m(),
            d0_2: n.d0_m * n.d0_m,
            inv_s2: 1.0 / (n.sigma_m * n.sigma_m),
            half_k: 0.5 * n.k,
            k2: n.k * n.k,
            k_is_2: n.k == 2.0,
            derivative: options.variance_derivative,
            fix_anchors: model.fix_anchors(),
        }
    }

    fn bound_at(&self, p: [f64; 2], options: &FimOptions) -> Bound {
        let (mut a, mut b, mut c) = (0.0, 0.0, 0.0);
        let mut used = 0;
        for an in &self.anchors {
            let dx = p[0] - an[0];
            let dy = p[1] - an[1];
            let d2 = dx * dx + dy * dy;
            if d2.is_nan() || d2 > self.range2 || d2 < MIN_DISTANCE_M * MIN_DISTANCE_M {
                continue;
            }
            // Per-range information 1/v + v′²/(2v²), with v = σ²(q + 1) and
            // v′ = σ²·K·q/d beyond d0, q = (d/d0)^K (model::range_information).
            let w = if d2 <= self.d0_2 {
                self.inv_s2
            } else {
                let r = d2 / self.d0_2;
                let q = if self.k_is_2 { r } else { r.powf(self.half_k) };
                let q1 = q + 1.0;
                let mut w = self.inv_s2 / q1;
                if self.derivative {
                    w += self.k2 * q * q / (2.0 * d2 * q1 * q1);
                }
                w
            };
            let s = w / d2;
            a += s * dx * dx;
            b += s * dx * dy;
            c += s * dy * dy;
            used += 1;
        }
        bound_from_fim(Matrix2::new(a, b, b, c), used, self.fix_anchors, options)
    }
}
