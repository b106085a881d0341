//! Probabilities as paper 000's information scores (whole percentages).

/// Probabilities as paper 000's information scores: [`percent`] of each (NaN as 0).
pub fn scores(probabilities: &[f64]) -> Vec<u8> {
    probabilities.iter().map(|&p| percent(p)).collect()
}

/// A probability as a whole percentage, round(100 · p) with p clamped to 0..=1, NaN as 0:
/// the one conversion behind the information scores and the map now's occupancy.
pub fn percent(p: f64) -> u8 {
    if p.is_nan() {
        0
    } else {
        (p.clamp(0.0, 1.0) * 100.0).round() as u8
    }
}
