//! Monte Carlo checks of the WLS estimator (paper 002 §2.1) against the PEB (§2.2): with
//! good geometry its RMSE is within 10 % of the PEB; with degenerate geometry it is
//! flagged degraded.

use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use roam_localization::{
    bound, estimate, Degraded, FimOptions, Range, RangingModel, ToaNoise, WlsOptions,
};

const DRAWS: usize = 4000;

fn paper_noise() -> ToaNoise {
    ToaNoise {
        sigma_m: 0.1,
        d0_m: 15.0,
        k: 2.0,
    }
}

/// Noisy ranges to every anchor whose true distance is within the sensing range
/// (roam-sim's default gate), drawn with roam-world's noise model (the sim's).
fn draw(model: &RangingModel, truth: [f64; 2], rng: &mut ChaCha8Rng) -> Vec<Range> {
    model
        .anchors()
        .iter()
        .enumerate()
        .filter_map(|(i, a)| {
            let d = ((truth[0] - a[0]).powi(2) + (truth[1] - a[1]).powi(2)).sqrt();
            model.in_range(d).then(|| Range {
                anchor: i,
                range_m: model.noise().measure(d, rng),
            })
        })
        .collect()
}

/// RMSE of the estimate over `DRAWS` draws, with no prior or with a prior off the truth.
fn rmse(model: &RangingModel, truth: [f64; 2], prior: Option<[f64; 2]>, seed: u64) -> f64 {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let mut sum = 0.0;
    for _ in 0..DRAWS {
        let ranges = draw(model, truth, &mut rng);
        let e = estimate(model, &ranges, prior, &WlsOptions::default()).expect("valid input");
        assert!(!e.degraded, "good geometry gave a degraded estimate: {e:?}");
        sum += (e.position[0] - truth[0]).powi(2) + (e.position[1] - truth[1]).powi(2);
    }
    (sum / DRAWS as f64).sqrt()
}

#[test]
fn rmse_is_within_ten_percent_of_the_peb_with_good_geometry() {
    let anchors = [
        [0.0, 0.0],
        [25.0, 0.0],
        [40.0, 15.0],
        [30.0, 35.0],
        [5.0, 30.0],
        [-10.0, 15.0],
        [15.0, 45.0],
    ];
    let model = RangingModel::new(&anchors, 30.0, paper_noise()).expect("valid");
    // Inside d0 of most anchors, and a point where several are beyond d0.
    let cases = [([15.0, 15.0], 1), ([28.0, 10.0], 2), ([5.0, 22.0], 3)];
    for (truth, seed) in cases {
        let peb = bound(&model, truth, &FimOptions::default()).peb;
        assert!(peb.is_finite());
        for prior in [None, Some([truth[0] + 1.5, truth[1] - 2.0])] {
            let r = rmse(&model, truth, prior, seed);
            let ratio = r / peb;
            assert!(
                (0.9..=1.1).contains(&ratio),
                "at {truth:?} prior {prior:?}: RMSE {r} vs PEB {peb} (ratio {ratio})"
            );
        }
    }
}

#[test]
fn degenerate_geometry_is_flagged_and_keeps_the_prior() {
    let prior = [12.0, 3.0];
    let truth = [10.0, 5.0];
    let cases: [(&[[f64; 2]], Degraded); 3] = [
        // Two anchors: two circles meet in two points.
        (
            &[[0.0, 0.0], [20.0, 0.0]],
            Degraded::TooFewAnchors { usable: 2 },
        ),
        // Three collinear anchors: ambiguous by reflection in their line.
        (
            &[[0.0, 0.0], [10.0, 0.0], [20.0, 0.0]],
            Degraded::CollinearAnchors,
        ),
        // One anchor.
        (&[[0.0, 0.0]], Degraded::TooFewAnchors { usable: 1 }),
    ];
    let mut rng = ChaCha8Rng::seed_from_u64(9);
    for (anchors, reason) in cases {
        let model = RangingModel::new(anchors, 30.0, paper_noise()).expect("valid");
        for _ in 0..DRAWS / 4 {
            let ranges = draw(&model, truth, &mut rng);
            for p in [Some(prior), None] {
                let e = estimate(&model, &ranges, p, &WlsOptions::default()).expect("valid");
                assert!(e.degraded);
                assert_eq!(e.reason, Some(reason));
                assert_eq!(e.peb, f64::INFINITY);
                assert!(e.position.iter().all(|x| x.is_finite()));
                if p.is_some() {
                    assert_eq!(e.position, prior);
                }
            }
        }
    }
}

#[test]
fn ranges_beyond_the_sensing_range_are_not_used() {
    let model = RangingModel::new(
        &[[0.0, 0.0], [20.0, 0.0], [10.0, 20.0]],
        30.0,
        paper_noise(),
    )
    .expect("valid");
    let ranges = [
        Range {
            anchor: 0,
            range_m: 11.2,
        },
        Range {
            anchor: 1,
            range_m: 11.2,
        },
        Range {
            anchor: 2,
            range_m: 45.0,
        },
    ];
    let e = estimate(&model, &ranges, Some([1.0, 1.0]), &WlsOptions::default()).expect("valid");
    assert!(e.degraded);
    assert_eq!(e.anchors_used, vec![0, 1]);
    assert_eq!(e.position, [1.0, 1.0]);
}

#[test]
fn bad_input_is_an_error_not_a_panic() {
    let model = RangingModel::new(
        &[[0.0, 0.0], [20.0, 0.0], [10.0, 20.0]],
        30.0,
        paper_noise(),
    )
    .expect("valid");
    let opts = WlsOptions::default();
    assert!(estimate(
        &model,
        &[Range {
            anchor: 3,
            range_m: 1.0
        }],
        None,
        &opts
    )
    .is_err());
    assert!(estimate(
        &model,
        &[Range {
            anchor: 0,
            range_m: f64::NAN
        }],
        None,
        &opts
    )
    .is_err());
    assert!(estimate(&model, &[], Some([f64::INFINITY, 0.0]), &opts).is_err());
    assert!(RangingModel::new(&[[f64::NAN, 0.0]], 30.0, paper_noise()).is_err());
    assert!(RangingModel::new(&[[0.0, 0.0]], -1.0, paper_noise()).is_err());
    let e = estimate(&model, &[], None, &opts).expect("no ranges is valid");
    assert!(e.degraded && e.position.iter().all(|x| x.is_finite()));
}
