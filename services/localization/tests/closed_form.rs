//! Closed-form checks of the FIM, CRB and PEB (paper 002 §2.2) against values derived by
//! hand.

use roam_localization::{
    bound, bounds_at, peb_field, FimOptions, GridRegion, RangingModel, ToaNoise,
};

/// Four anchors at distance `r` from the origin, at 0°, 90°, 180° and 270°.
fn square(r: f64, sigma: f64) -> RangingModel {
    let noise = ToaNoise {
        sigma_m: sigma,
        d0_m: 15.0,
        k: 2.0,
    };
    RangingModel::new(&[[r, 0.0], [0.0, r], [-r, 0.0], [0.0, -r]], 30.0, noise)
        .expect("a valid model")
}

fn close(a: f64, b: f64, rel: f64) -> bool {
    (a - b).abs() <= rel * b.abs().max(1e-300)
}

/// Robot at the centre of a square of four anchors at r = 10 m < d0 = 15 m, σ = 0.1 m.
///
/// Every range has variance σ² (paper 002 §2.1, d ≤ d0) and v′ = 0, so each contributes
/// u uᵀ/σ². The unit vectors are ±e_x and ±e_y: e_x e_xᵀ + e_x e_xᵀ + e_y e_yᵀ + e_y e_yᵀ
/// = 2I, so F = (2/σ²) I, CRB = F⁻¹ = (σ²/2) I, tr CRB = σ², PEB = σ = 0.1 m, with or
/// without the variance-derivative term.
#[test]
fn centre_of_a_square_within_d0() {
    let model = square(10.0, 0.1);
    for variance_derivative in [true, false] {
        let opts = FimOptions {
            variance_derivative,
            ..FimOptions::default()
        };
        let b = bound(&model, [0.0, 0.0], &opts);
        assert!(!b.degraded);
        assert_eq!(b.anchors_used, 4);
        assert!(close(b.fim[(0, 0)], 200.0, 1e-12) && close(b.fim[(1, 1)], 200.0, 1e-12));
        assert!(b.fim[(0, 1)].abs() < 1e-9);
        assert!(close(b.crb[(0, 0)], 0.005, 1e-12) && close(b.crb[(1, 1)], 0.005, 1e-12));
        assert!(close(b.peb, 0.1, 1e-12), "PEB {} != 0.1", b.peb);
    }
}

/// The same square at r = 20 m, beyond d0 = 15 m (K = 2, σ = 1 m to make the derivative
/// term visible).
///
/// q = (d/d0)^K = (20/15)² = 16/9, so v = σ²(q + 1) = (25/9)σ² and
/// v′ = σ²·K·d^(K−1)/d0^K = σ²·2·20/225 = (8/45)σ².
/// - Without the derivative term each range carries w = 1/v = 9/(25σ²) = 0.36 /m², so
///   F = 2w I, CRB = I/(2w), PEB = √(2/(2w)) = √v = (5/3)σ = 1.6667 m.
/// - With it, w = 1/v + v′²/(2v²) = 0.36 + (8/45)²/(2·(25/9)²) = 0.36 + 0.002048
///   = 0.362048 /m² (the second term is K²q²/(2d²(q+1)²), independent of σ), and
///   PEB = 1/√w = 1.661954 m.
#[test]
fn centre_of_a_square_beyond_d0() {
    let model = square(20.0, 1.0);
    let cases = [(false, 0.36), (true, 0.36 + 0.002048)];
    for (variance_derivative, w) in cases {
        let opts = FimOptions {
            variance_derivative,
            ..FimOptions::default()
        };
        let b = bound(&model, [0.0, 0.0], &opts);
        assert!(!b.degraded);
        assert!(
            close(b.fim[(0, 0)], 2.0 * w, 1e-12),
            "{} vs {}",
            b.fim[(0, 0)],
            2.0 * w
        );
        assert!(close(b.crb[(1, 1)], 1.0 / (2.0 * w), 1e-12));
        assert!(close(b.peb, 1.0 / w.sqrt(), 1e-12));
    }
    let without = bound(
        &model,
        [0.0, 0.0],
        &FimOptions {
            variance_derivative: false,
            ..FimOptions::default()
        },
    );
    assert!(close(without.peb, 5.0 / 3.0, 1e-12));
}

/// The grid kernel (`peb_field`) agrees with the point bound, inside and beyond d0, for K
/// = 2 and for a non-integer K.
#[test]
fn field_kernel_matches_point_bound() {
    for k in [2.0, 2.7, 0.0] {
        let noise = ToaNoise {
            sigma_m: 0.3,
            d0_m: 12.0,
            k,
        };
        let model = RangingModel::new(
            &[[0.0, 0.0], [40.0, 5.0], [10.0, 35.0], [33.0, 30.0]],
            30.0,
            noise,
        )
        .expect("valid");
        let region = GridRegion {
            origin: [-5.0, -5.0],
            resolution_m: 1.7,
            width: 30,
            height: 28,
        };
        for variance_derivative in [true, false] {
            let opts = FimOptions {
                variance_derivative,
                ..FimOptions::default()
            };
            let field = peb_field(&model, &region, &opts).expect("field");
            let points: Vec<[f64; 2]> = (0..region.height)
                .flat_map(|y| (0..region.width).map(move |x| (x, y)))
                .map(|(x, y)| region.cell_center(x, y))
                .collect();
            let bounds = bounds_at(&model, &points, &opts).expect("points");
            for (f, b) in field.peb.iter().zip(&bounds) {
                if b.peb.is_finite() {
                    assert!(close(f64::from(*f), b.peb, 1e-6), "{f} vs {}", b.peb);
                } else {
                    assert_eq!(*f, f32::INFINITY);
                }
            }
        }
    }
}

/// The variance derivative of the model matches a finite difference of roam-sim's
/// variance away from the step at d0.
#[test]
fn variance_derivative_matches_difference() {
    let model = square(10.0, 0.2);
    for d in [3.0, 14.0, 16.0, 22.5, 29.0] {
        let h = 1e-5;
        let fd = (model.variance(d + h) - model.variance(d - h)) / (2.0 * h);
        assert!((model.variance_derivative(d) - fd).abs() < 1e-8, "at {d}");
    }
}
