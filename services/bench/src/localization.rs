//! `roam bench localization`: WLS estimates per second with 7 anchors (ES3's
//! constellation) and the time of a 500 × 500 PEB field, in process.

use std::time::Instant;

use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use roam_localization::field::{peb_field, GridRegion};
use roam_localization::{estimate, FimOptions, Range, RangingModel, WlsOptions};
use serde::Serialize;

use crate::BenchError;

#[derive(Debug, Clone, Serialize)]
pub struct LocalizationBench {
    pub anchors: usize,
    pub estimates: usize,
    pub estimates_per_s: f64,
    pub field_cells: usize,
    pub field_500_ms: f64,
}

pub fn localization(estimates: usize) -> Result<LocalizationBench, BenchError> {
    let setup = |e: String| BenchError::Setup(e);
    let path =
        std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../config/scenarios/es3.yaml");
    let (_, scenario) =
        roam_world::scenario::load_or_builtin(Some(&path)).map_err(|e| setup(e.to_string()))?;
    let anchors: Vec<[f64; 2]> = scenario.file.anchors.iter().map(|a| a.at).collect();
    let model = RangingModel::from_spec(&anchors, &scenario.file.sensing)
        .map_err(|e| setup(e.to_string()))?;
    let noise = *model.noise();
    let centre = anchors.first().copied().unwrap_or([0.0, 0.0]);
    let mut rng = ChaCha8Rng::seed_from_u64(1);
    // Scans at points around the centre anchor, drawn before timing.
    let scans: Vec<(Vec<Range>, [f64; 2])> = (0..estimates.min(10_000))
        .map(|k| {
            let angle = k as f64 * 0.618;
            let p = [
                centre[0] + 12.0 * angle.cos(),
                centre[1] + 12.0 * angle.sin(),
            ];
            let ranges = anchors
                .iter()
                .enumerate()
                .map(|(anchor, a)| Range {
                    anchor,
                    range_m: noise.measure((a[0] - p[0]).hypot(a[1] - p[1]), &mut rng),
                })
                .collect();
            (ranges, p)
        })
        .collect();
    let options = WlsOptions::default();
    let started = Instant::now();
    let mut done = 0;
    while done < estimates {
        let (ranges, p) = &scans[done % scans.len()];
        let e = estimate(&model, ranges, Some(*p), &options).map_err(|e| setup(e.to_string()))?;
        std::hint::black_box(e);
        done += 1;
    }
    let estimates_per_s = done as f64 / started.elapsed().as_secs_f64();
    let region = GridRegion {
        origin: [centre[0] - 31.0, centre[1] - 31.0],
        resolution_m: 62.0 / 500.0,
        width: 500,
        height: 500,
    };
    let started = Instant::now();
    let field =
        peb_field(&model, &region, &FimOptions::default()).map_err(|e| setup(e.to_string()))?;
    let field_500_ms = started.elapsed().as_secs_f64() * 1000.0;
    Ok(LocalizationBench {
        anchors: anchors.len(),
        estimates: done,
        estimates_per_s,
        field_cells: field.peb.len(),
        field_500_ms,
    })
}
