//! The PEB field (paper 002 §2.2) over ES1's constellation (config/scenarios/es1.yaml),
//! and the PEB gradient.

use std::path::Path;

use roam_localization::{
    bound, crb_field, peb_field, peb_gradient, FimOptions, GridRegion, RangingModel,
    DEFAULT_GRADIENT_STEP_M,
};

fn es1() -> (RangingModel, GridRegion) {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../config/scenarios/es1.yaml");
    let s = roam_world::scenario::load(&path, 10_000_000).expect("es1 loads");
    let anchors: Vec<[f64; 2]> = s.file.anchors.iter().map(|a| a.at).collect();
    let model = RangingModel::from_spec(&anchors, &s.file.sensing).expect("es1 is valid");
    let m = &s.occupancy.meta;
    let region = GridRegion {
        origin: [m.origin.x, m.origin.y],
        resolution_m: m.resolution,
        width: m.width as usize,
        height: m.height as usize,
    };
    (model, region)
}

fn in_range(model: &RangingModel, p: [f64; 2]) -> usize {
    model
        .anchors()
        .iter()
        .filter(|a| model.in_range((p[0] - a[0]).hypot(p[1] - a[1])))
        .count()
}

/// +∞ where fewer than two anchors are in range; finite where three or more are (ES1's
/// anchors are never collinear); both occur, and the well-covered middle is finite.
#[test]
fn es1_field_is_infinite_outside_coverage_and_finite_in_the_middle() {
    let (model, region) = es1();
    let opts = FimOptions::default();
    let field = crb_field(&model, &region, &opts).expect("field");
    let peb = peb_field(&model, &region, &opts).expect("field");
    assert_eq!(field.peb, peb.peb);
    let (mut infinite, mut finite) = (0, 0);
    for y in 0..region.height {
        for x in 0..region.width {
            let i = y * region.width + x;
            let v = field.peb[i];
            assert!(!v.is_nan() && !field.crb_xx[i].is_nan() && !field.crb_xy[i].is_nan());
            let n = in_range(&model, region.cell_center(x, y));
            if n < 2 {
                assert_eq!(v, f32::INFINITY, "cell ({x}, {y}) hears {n} anchors");
            }
            if n >= 3 {
                assert!(
                    v.is_finite() && v > 0.0,
                    "cell ({x}, {y}) hears {n} anchors"
                );
            }
            if v.is_finite() {
                finite += 1;
            } else {
                infinite += 1;
            }
        }
    }
    assert!(
        infinite > 0 && finite > 0,
        "{infinite} infinite, {finite} finite"
    );
    // ES1's waypoints and the corridor north of the route are covered by three or more.
    for p in [[10.0, 16.0], [60.0, 16.0], [35.0, 28.0]] {
        assert!(in_range(&model, p) >= 3);
        let b = bound(&model, p, &opts);
        assert!(b.peb.is_finite() && b.peb < 1.0, "PEB at {p:?}: {}", b.peb);
    }
}

/// The gradient by central differences agrees with a finer difference and points uphill;
/// it is `None` where the PEB is infinite.
#[test]
fn gradient_matches_a_finer_difference() {
    let (model, _) = es1();
    let opts = FimOptions::default();
    let p = [35.0, 28.0];
    let g = peb_gradient(&model, p, DEFAULT_GRADIENT_STEP_M, &opts)
        .expect("valid")
        .expect("finite PEB");
    let fine = peb_gradient(&model, p, DEFAULT_GRADIENT_STEP_M / 10.0, &opts)
        .expect("valid")
        .expect("finite PEB");
    let norm = g[0].hypot(g[1]);
    assert!(norm > 0.0);
    assert!((g[0] - fine[0]).hypot(g[1] - fine[1]) < 1e-3 * norm.max(1e-6));
    // A small step along the gradient raises the PEB.
    let step = 0.01 / norm;
    let up = bound(&model, [p[0] + step * g[0], p[1] + step * g[1]], &opts).peb;
    assert!(up > bound(&model, p, &opts).peb);
    // Far from every anchor: no gradient.
    assert_eq!(peb_gradient(&model, [500.0, 500.0], 0.05, &opts), Ok(None));
    assert!(peb_gradient(&model, p, 0.0, &opts).is_err());
}

#[test]
fn oversized_or_bad_regions_are_refused() {
    let (model, _) = es1();
    let opts = FimOptions::default();
    for region in [
        GridRegion {
            origin: [0.0, 0.0],
            resolution_m: 0.1,
            width: 5000,
            height: 5000,
        },
        GridRegion {
            origin: [0.0, 0.0],
            resolution_m: 0.0,
            width: 5,
            height: 5,
        },
        GridRegion {
            origin: [f64::NAN, 0.0],
            resolution_m: 1.0,
            width: 5,
            height: 5,
        },
        GridRegion {
            origin: [0.0, 0.0],
            resolution_m: 1.0,
            width: usize::MAX,
            height: 2,
        },
    ] {
        assert!(peb_field(&model, &region, &opts).is_err());
    }
}
