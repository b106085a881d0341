//! Two-anchor fixes (`sensing.fix_anchors: 2`): the estimate near the last fix is taken
//! when its mirror image in the anchors' line is clearly farther; the tracker follows a
//! robot through ground where only two anchors are heard; the PEB field and the
//! estimator follow one rule; the default (three) is unchanged.

use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use roam_localization::field::{peb_field, GridRegion};
use roam_localization::{
    bound, estimate, Degraded, FimOptions, Range, RangingModel, ToaNoise, Tracker, WlsOptions,
};
use roam_proto::sim::{AnchorRange, RangeScan};
use roam_world::scenario::SensingSpec;

const ANCHORS: [[f64; 2]; 2] = [[0.0, 0.0], [10.0, 0.0]];

fn noise() -> ToaNoise {
    ToaNoise {
        sigma_m: 0.1,
        d0_m: 15.0,
        k: 2.0,
    }
}

fn model(fix_anchors: usize) -> RangingModel {
    RangingModel::new(&ANCHORS, 30.0, noise())
        .and_then(|m| m.with_fix_anchors(fix_anchors))
        .expect("model")
}

fn exact(truth: [f64; 2], anchors: &[[f64; 2]]) -> Vec<Range> {
    anchors
        .iter()
        .enumerate()
        .map(|(anchor, a)| Range {
            anchor,
            range_m: (truth[0] - a[0]).hypot(truth[1] - a[1]),
        })
        .collect()
}

#[test]
fn two_anchors_and_a_prior_fix_the_point_near_the_prior_not_its_mirror() {
    let truth = [4.0, 3.0];
    let ranges = exact(truth, &ANCHORS);
    let options = WlsOptions::default();
    for (prior, expect) in [([4.3, 2.8], [4.0, 3.0]), ([3.8, -3.3], [4.0, -3.0])] {
        let e = estimate(&model(2), &ranges, Some(prior), &options).expect("estimate");
        assert!(!e.degraded, "{prior:?}: {:?}", e.reason);
        assert!(
            (e.position[0] - expect[0]).abs() < 1e-6 && (e.position[1] - expect[1]).abs() < 1e-6,
            "{prior:?} -> {:?}",
            e.position
        );
        assert!(e.peb.is_finite() && e.peb < 0.5, "PEB {}", e.peb);
        assert_eq!(e.anchors_used, [0, 1]);
    }
}

#[test]
fn two_anchors_without_a_clear_prior_or_with_the_default_rule_are_degraded() {
    let truth = [4.0, 3.0];
    let ranges = exact(truth, &ANCHORS);
    let options = WlsOptions::default();
    // No prior: nothing tells the point from its mirror.
    let e = estimate(&model(2), &ranges, None, &options).expect("estimate");
    assert_eq!(e.reason, Some(Degraded::CollinearAnchors));
    // A prior on the anchors' line is as near the mirror as the point.
    let e = estimate(&model(2), &ranges, Some([4.0, 0.2]), &options).expect("estimate");
    assert_eq!(e.reason, Some(Degraded::Ambiguous));
    assert_eq!(
        e.position,
        [4.0, 0.2],
        "a degraded estimate keeps the prior"
    );
    // The default rule: three anchors.
    let e = estimate(&model(3), &ranges, Some([4.1, 3.0]), &options).expect("estimate");
    assert_eq!(e.reason, Some(Degraded::TooFewAnchors { usable: 2 }));
    // Three anchors in one line, with a prior: fixed under the two-anchor rule only.
    let line = [[0.0, 0.0], [5.0, 0.0], [10.0, 0.0]];
    let three = |fix| {
        RangingModel::new(&line, 30.0, noise())
            .and_then(|m| m.with_fix_anchors(fix))
            .expect("model")
    };
    let ranges = exact(truth, &line);
    let e = estimate(&three(2), &ranges, Some([4.2, 3.1]), &options).expect("estimate");
    assert!(!e.degraded, "{:?}", e.reason);
    let e = estimate(&three(3), &ranges, Some([4.2, 3.1]), &options).expect("estimate");
    assert_eq!(e.reason, Some(Degraded::CollinearAnchors));
}

#[test]
fn the_bound_and_the_field_follow_the_estimators_rule() {
    let at = [4.0, 3.0];
    let b2 = bound(&model(2), at, &FimOptions::default());
    let b3 = bound(&model(3), at, &FimOptions::default());
    assert!(!b2.degraded && b2.peb.is_finite());
    assert!(b3.degraded && b3.peb.is_infinite());
    let region = GridRegion {
        origin: [0.0, 1.0],
        resolution_m: 1.0,
        width: 10,
        height: 5,
    };
    let f2 = peb_field(&model(2), &region, &FimOptions::default()).expect("field");
    let f3 = peb_field(&model(3), &region, &FimOptions::default()).expect("field");
    assert!(f2.peb.iter().all(|p| p.is_finite()));
    assert!(f3.peb.iter().all(|p| p.is_infinite()));
    // The field's cell and the bound at its centre agree.
    let centre = [4.5, 3.5];
    let cell = 2 * region.width + 4;
    let b = bound(&model(2), centre, &FimOptions::default());
    assert!((f64::from(f2.peb[cell]) - b.peb).abs() < 1e-4 * b.peb);
}

#[test]
fn the_tracker_follows_a_robot_from_three_anchors_into_two() {
    let sensing = SensingSpec {
        range_m: 12.0,
        fix_anchors: 2,
        ..SensingSpec::default()
    };
    // A third anchor up the y axis, heard for the first 27 steps or so, then lost.
    let anchors = [[0.0, 0.0], [10.0, 0.0], [0.0, 16.0]];
    let mut tracker = Tracker::new(sensing, FimOptions::default());
    let mut rng = ChaCha8Rng::seed_from_u64(7);
    let mut worst: f64 = 0.0;
    let mut two_anchor_fixes = 0;
    for step in 0..60u64 {
        let truth = [2.0 + 0.15 * step as f64, 7.0 - 0.05 * step as f64];
        let ranges = anchors
            .iter()
            .enumerate()
            .filter_map(|(i, a)| {
                let d = (truth[0] - a[0]).hypot(truth[1] - a[1]);
                (d <= sensing.range_m).then(|| AnchorRange {
                    anchor: format!("a{i}"),
                    at: *a,
                    range_m: noise().measure(d, &mut rng),
                })
            })
            .collect::<Vec<_>>();
        let heard = ranges.len();
        let scan = RangeScan {
            robot: "r".into(),
            step,
            time_s: step as f64 * 0.4,
            ranges,
        };
        let e = tracker.on_scan(&scan).expect("estimate");
        assert!(!e.degraded, "step {step}: {heard} anchors, degraded");
        if heard == 2 {
            two_anchor_fixes += 1;
        }
        let error = (e.position[0] - truth[0]).hypot(e.position[1] - truth[1]);
        worst = worst.max(error);
    }
    assert!(two_anchor_fixes > 25, "{two_anchor_fixes} two-anchor fixes");
    assert!(worst < 0.5, "worst error {worst} m");
}

#[test]
fn a_site_cannot_ask_for_fewer_than_two_or_more_than_eight_anchors() {
    for bad in [0, 1, 9, 1_000_000] {
        assert!(
            RangingModel::new(&ANCHORS, 30.0, noise())
                .and_then(|m| m.with_fix_anchors(bad))
                .is_err(),
            "{bad}"
        );
    }
}
