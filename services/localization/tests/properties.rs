//! Property tests over random constellations (paper 002 §2): no NaN, no panic; the PEB
//! never below 2/√tr(F) (for a 2 × 2 SPD matrix tr F⁻¹ = tr F / det F ≥ 4 / tr F, as
//! (a + c)² − 4(ac − b²) = (a − c)² + 4b² ≥ 0); degraded exactly when the FIM is
//! singular.

use proptest::prelude::*;
use roam_localization::{
    bound, estimate, peb_field, FimOptions, GridRegion, Range, RangingModel, ToaNoise, WlsOptions,
    MIN_FIX_ANCHORS,
};

/// A constellation: 1–10 anchors, either anywhere or (to hit exact singularity) on one
/// line through the point; noise and range from moderate bounds ((s_r/d0)^K ≤ 12³).
fn setup() -> impl Strategy<Value = (Vec<[f64; 2]>, [f64; 2], RangingModel, bool, bool)> {
    (
        prop::collection::vec((-50.0..50.0f64, -50.0..50.0f64), 1..=10),
        (-60.0..60.0f64, -60.0..60.0f64),
        (0.01..1.0f64, 5.0..30.0f64, 0.0..3.0f64, 5.0..60.0f64),
        any::<bool>(),
        any::<bool>(),
        0.0..std::f64::consts::PI,
    )
        .prop_map(
            |(raw, p, (sigma, d0, k, range), derivative, collinear, angle)| {
                let p = [p.0, p.1];
                let anchors: Vec<[f64; 2]> = if collinear {
                    // On the line through p with direction `angle`, at signed offsets.
                    raw.iter()
                        .map(|&(t, _)| {
                            let t = if t.abs() < 0.5 { t + 1.0 } else { t };
                            [p[0] + t * angle.cos(), p[1] + t * angle.sin()]
                        })
                        .collect()
                } else {
                    raw.iter().map(|&(x, y)| [x, y]).collect()
                };
                let noise = ToaNoise {
                    sigma_m: sigma,
                    d0_m: d0,
                    k,
                };
                let model = RangingModel::new(&anchors, range, noise).expect("valid model");
                (anchors, p, model, derivative, collinear)
            },
        )
}

/// The largest |sin| between the point's unit vectors to the anchors in range, and how
/// many are in range.
fn max_sine(model: &RangingModel, p: [f64; 2]) -> (f64, usize) {
    let units: Vec<[f64; 2]> = model
        .anchors()
        .iter()
        .filter_map(|a| {
            let (dx, dy) = (p[0] - a[0], p[1] - a[1]);
            let d = dx.hypot(dy);
            (model.in_range(d) && d > 1e-9).then(|| [dx / d, dy / d])
        })
        .collect();
    let mut s: f64 = 0.0;
    for (i, u) in units.iter().enumerate() {
        for v in &units[i + 1..] {
            s = s.max((u[0] * v[1] - u[1] * v[0]).abs());
        }
    }
    (s, units.len())
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(2000))]

    #[test]
    fn bound_is_never_nan_and_obeys_the_trace_inequality(
        (_anchors, p, model, variance_derivative, collinear) in setup()
    ) {
        let opts = FimOptions { variance_derivative, ..FimOptions::default() };
        let b = bound(&model, p, &opts);
        prop_assert!(!b.peb.is_nan());
        prop_assert!(b.crb.iter().all(|x| !x.is_nan()));
        prop_assert!(b.fim.iter().all(|x| x.is_finite()));
        prop_assert_eq!(b.degraded, b.peb.is_infinite());
        if b.peb.is_finite() {
            let tr = b.fim.trace();
            prop_assert!(b.peb >= 2.0 / tr.sqrt() * (1.0 - 1e-12), "PEB {} < 2/sqrt(tr F) {}", b.peb, 2.0 / tr.sqrt());
        }
        // Degraded exactly when the estimator has no fix: fewer than MIN_FIX_ANCHORS (3)
        // anchors in range, or all in line with the point (singular); three or more
        // with any pair at more than 0.05 rad are not (with these parameters the weights
        // differ by at most ~2000×, so λ_min/λ_max stays above 1e-7, far from the 1e-9
        // threshold).
        let (s, n) = max_sine(&model, p);
        if n < MIN_FIX_ANCHORS || (collinear && s < 1e-7) {
            prop_assert!(b.degraded, "no fix, yet not degraded: n {n} {b:?}");
        }
        if n >= MIN_FIX_ANCHORS && s > 0.05 {
            prop_assert!(!b.degraded, "regular FIM degraded: n {n} s {s} {b:?}");
        }
        // And against an independent eigen-decomposition.
        let eig = b.fim.symmetric_eigen().eigenvalues;
        let (lo, hi) = (eig.min(), eig.max());
        if n >= MIN_FIX_ANCHORS && hi > 0.0 && lo / hi > 1e-8 {
            prop_assert!(!b.degraded);
        }
        if hi <= 0.0 || lo / hi < 1e-10 {
            prop_assert!(b.degraded);
        }
    }

    #[test]
    fn estimate_is_never_nan(
        (anchors, p, model, _d, _c) in setup(),
        noise in prop::collection::vec(-3.0..3.0f64, 10),
        with_prior in any::<bool>(),
    ) {
        let ranges: Vec<Range> = anchors
            .iter()
            .enumerate()
            .map(|(i, a)| Range {
                anchor: i,
                range_m: (p[0] - a[0]).hypot(p[1] - a[1]) + noise[i],
            })
            .collect();
        let prior = with_prior.then_some([p[0] + noise[0], p[1] - noise[1]]);
        let e = estimate(&model, &ranges, prior, &WlsOptions::default()).expect("valid input");
        prop_assert!(e.position.iter().all(|x| x.is_finite()));
        prop_assert!(!e.peb.is_nan());
        prop_assert!(e.covariance.iter().all(|x| !x.is_nan()));
        prop_assert_eq!(e.degraded, e.peb.is_infinite());
        prop_assert_eq!(e.degraded, e.reason.is_some());
        if e.degraded {
            if let Some(q) = prior {
                prop_assert_eq!(e.position, q);
            }
        }
    }

    #[test]
    fn field_is_never_nan(
        (_anchors, _p, model, variance_derivative, _c) in setup(),
        origin in (-80.0..0.0f64, -80.0..0.0f64),
        resolution in 0.5..10.0f64,
    ) {
        let region = GridRegion { origin: [origin.0, origin.1], resolution_m: resolution, width: 17, height: 13 };
        let opts = FimOptions { variance_derivative, ..FimOptions::default() };
        let f = peb_field(&model, &region, &opts).expect("valid region");
        prop_assert_eq!(f.peb.len(), 17 * 13);
        prop_assert!(f.peb.iter().all(|x| !x.is_nan() && *x > 0.0));
    }
}
