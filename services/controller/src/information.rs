//! The information-seeking field of paper 002 §3: the PEB of the anchor constellation
//! (paper 002 §2.2) and the direction in which it falls fastest.

use roam_localization::fim::{bound, FimOptions};
use roam_localization::model::RangingModel;
use roam_localization::{peb_gradient, DEFAULT_GRADIENT_STEP_M};

use crate::obstacle_field::unit;

/// The PEB field of a constellation, with the IS force derived from it.
#[derive(Debug, Clone)]
pub struct InformationField {
    model: RangingModel,
    fim: FimOptions,
}

impl InformationField {
    /// The field of `model`'s anchors and sensing model; `fim` as the localization
    /// service forms its bounds (roam's default: with the variance-derivative term).
    pub fn new(model: RangingModel, fim: FimOptions) -> InformationField {
        InformationField { model, fim }
    }

    /// The PEB √tr(F⁻¹) at `p` over the anchors in sensing range (paper 002 §2.2),
    /// metres; `None` where it is unbounded (the FIM is singular) or `p` is not finite.
    pub fn peb_m(&self, p: [f64; 2]) -> Option<f64> {
        if !(p[0].is_finite() && p[1].is_finite()) {
            return None;
        }
        let b = bound(&self.model, p, &self.fim);
        (!b.degraded && b.peb.is_finite()).then_some(b.peb)
    }

    /// The IS force f_is at `p`: the unit vector of −∇PEB (paper 002 §3; DESIGN.md: the
    /// negative gradient of the PEB at the estimated position).
    ///
    /// **Normalised to unit length** (roam's choice; paper 002 does not give f_is's
    /// magnitude): the PEB's slope is about 0.01 m per metre inside coverage, so a raw
    /// gradient would be negligible against the unit attractive force and the weights
    /// z_is = 0.8–0.9 of §4 would mean nothing; with a unit f_is, z_is is directly the
    /// IS force's strength relative to z_a · f_a. Zero where the PEB is unbounded or
    /// flat. The gradient is roam-localization's central difference with its default
    /// step ([`DEFAULT_GRADIENT_STEP_M`]).
    pub fn is_force(&self, p: [f64; 2]) -> [f64; 2] {
        match peb_gradient(&self.model, p, DEFAULT_GRADIENT_STEP_M, &self.fim) {
            Ok(Some(g)) => unit([-g[0], -g[1]]),
            _ => [0.0, 0.0],
        }
    }

    /// The ranging model (anchors, sensing range, noise).
    pub fn model(&self) -> &RangingModel {
        &self.model
    }

    pub fn fim_options(&self) -> &FimOptions {
        &self.fim
    }

    /// How many anchors are within sensing range of `p` (paper 002 §2.1: d ≤ s_r).
    pub fn coverage(&self, p: [f64; 2]) -> usize {
        self.model
            .anchors()
            .iter()
            .filter(|a| self.model.in_range((a[0] - p[0]).hypot(a[1] - p[1])))
            .count()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use roam_localization::ToaNoise;

    fn field(anchors: &[[f64; 2]]) -> InformationField {
        let noise = ToaNoise {
            sigma_m: 0.1,
            d0_m: 15.0,
            k: 2.0,
        };
        let model = RangingModel::new(anchors, 30.0, noise).expect("model");
        InformationField::new(model, FimOptions::default())
    }

    #[test]
    fn the_peb_matches_the_closed_form_and_is_none_without_a_fix() {
        // Three anchors within d0 on the axes: F = diag(2/σ², 1/σ²), PEB = σ√(1/2 + 1).
        let f = field(&[[10.0, 0.0], [0.0, 10.0], [-10.0, 0.0]]);
        let peb = f.peb_m([0.0, 0.0]).expect("finite");
        assert!((peb - 0.1 * 1.5f64.sqrt()).abs() < 1e-12, "{peb}");
        // Two anchors: an invertible FIM, but no fix (the estimator needs three).
        let two = field(&[[10.0, 0.0], [0.0, 10.0]]);
        assert_eq!(two.peb_m([0.0, 0.0]), None);
        // No anchor in range.
        assert_eq!(f.peb_m([100.0, 0.0]), None);
        assert_eq!(f.is_force([100.0, 0.0]), [0.0, 0.0]);
        assert_eq!(f.peb_m([f64::NAN, 0.0]), None);
        assert_eq!(f.coverage([0.0, 0.0]), 3);
        assert_eq!(f.coverage([100.0, 0.0]), 0);
    }

    #[test]
    fn the_is_force_is_a_unit_vector_downhill() {
        // Three anchors around the origin; beyond d0 of all of them the PEB grows with
        // the distance from the triangle, so f_is at (0, -20) points back up (+y).
        let f = field(&[[-10.0, 10.0], [10.0, 10.0], [0.0, 5.0]]);
        let p = [0.0, -12.0];
        let v = f.is_force(p);
        assert!((v[0].hypot(v[1]) - 1.0).abs() < 1e-12);
        assert!(v[0].abs() < 1e-9, "symmetric: no x component, {v:?}");
        assert!(v[1] > 0.99, "{v:?}");
        // A step along f_is lowers the PEB.
        let a = f.peb_m(p).expect("finite");
        let b = f
            .peb_m([p[0] + 0.1 * v[0], p[1] + 0.1 * v[1]])
            .expect("finite");
        assert!(b < a, "{b} < {a}");
    }
}
