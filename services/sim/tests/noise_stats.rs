//! The range noise matches paper 002's model: variance σ² up to d0 and σ²((d/d0)^K + 1)
//! beyond, zero mean; checked on the sampler and through the sim's sensor.

mod common;

use roam_sim::Sim;
use roam_world::noise::{self, ToaNoise};
use roam_world::scenario::SensingSpec;

/// Sample mean and unbiased sample variance.
fn mean_var(xs: &[f64]) -> (f64, f64) {
    let n = xs.len() as f64;
    let mean = xs.iter().sum::<f64>() / n;
    let var = xs.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / (n - 1.0);
    (mean, var)
}

/// Checks samples of `d + n` against the model. For Gaussian samples the sample
/// variance has a relative standard error of √(2/(N−1)) and the mean a standard error
/// of σ/√N; both are allowed 5 standard errors (a false alarm about once in 3 million).
fn check(samples: &[f64], d: f64, model: &ToaNoise) {
    let n = samples.len() as f64;
    let (mean, var) = mean_var(samples);
    let want = model.variance(d);
    let rel_se = (2.0 / (n - 1.0)).sqrt();
    assert!(
        ((var - want) / want).abs() < 5.0 * rel_se,
        "d = {d} m: sample variance {var:.6e}, model {want:.6e} (tolerance {:.2}%)",
        500.0 * rel_se
    );
    assert!(
        (mean - d).abs() < 5.0 * want.sqrt() / n.sqrt(),
        "d = {d} m: sample mean {mean}, want {d}"
    );
}

#[test]
fn sampled_ranges_have_the_models_variance() {
    let model = ToaNoise::from_spec(&SensingSpec::default());
    assert_eq!((model.sigma_m, model.d0_m, model.k), (0.10, 15.0, 2.0));
    for (i, d) in [1.0, 5.0, 15.0, 15.01, 25.0, 30.0, 60.0]
        .into_iter()
        .enumerate()
    {
        let mut rng = noise::stream(2024, &format!("stats/{i}"));
        let samples: Vec<f64> = (0..200_000).map(|_| model.measure(d, &mut rng)).collect();
        check(&samples, d, &model);
    }
    // The model itself: σ² below d0, σ²((d/d0)^K + 1) beyond (25 m: 0.01 · (25/9 + 1)).
    assert!((model.variance(5.0) - 0.01).abs() < 1e-15);
    assert!((model.variance(25.0) - 0.01 * (625.0 / 225.0 + 1.0)).abs() < 1e-15);
    // A different K is an exponent, not a factor.
    let k3 = ToaNoise { k: 3.0, ..model };
    assert!((k3.variance(30.0) - 0.01 * 9.0).abs() < 1e-15);
}

#[test]
fn the_sims_ranges_have_the_models_variance() {
    // A robot standing still (no command: no transition noise) with anchors 5, 15 and
    // 25 m away, and one at 40 m, outside the 30 m range.
    let text = "
name: stats
map: { grid: { size_m: [50.0, 10.0], resolution: 1.0 } }
sensing: { observation_radius_m: 0.0 }
anchors:
  - { name: d5, at: [5.5, 5.5] }
  - { name: d15, at: [15.5, 5.5] }
  - { name: d25, at: [25.5, 5.5] }
  - { name: d40, at: [40.5, 5.5] }
robots: [ { name: r, at: [0.5, 5.5] } ]
";
    let scenario = common::inline(text);
    let mut sim = Sim::new(&scenario, 99).expect("sim");
    let model = ToaNoise::from_spec(&sim.params().sensing);
    let mut samples = vec![Vec::new(); 4];
    for _ in 0..40_000 {
        let report = sim.step(&[]).expect("step");
        let readings = &report.robots[0].readings;
        assert_eq!(
            readings.truth,
            [0.5, 5.5],
            "a robot without commands stays put"
        );
        assert_eq!(readings.ranges.len(), 3, "the 40 m anchor is out of range");
        for r in &readings.ranges {
            samples[r.anchor].push(r.range_m);
        }
    }
    for (anchor, d) in [(0, 5.0), (1, 15.0), (2, 25.0)] {
        check(&samples[anchor], d, &model);
    }
}
