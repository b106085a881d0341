//! Medians and ratios over days, the only statistics the report uses.

/// The median of `values` (the mean of the middle two for an even count; NaNs left
/// out); `None` when there is none.
pub fn median(values: impl IntoIterator<Item = f64>) -> Option<f64> {
    let mut v: Vec<f64> = values.into_iter().filter(|x| !x.is_nan()).collect();
    v.sort_by(f64::total_cmp);
    let n = v.len();
    match n {
        0 => None,
        _ if n % 2 == 1 => Some(v[n / 2]),
        _ => Some((v[n / 2 - 1] + v[n / 2]) / 2.0),
    }
}

/// The mean; `None` when empty.
pub fn mean(values: impl IntoIterator<Item = f64>) -> Option<f64> {
    let (sum, n) = values
        .into_iter()
        .fold((0.0, 0usize), |(s, n), x| (s + x, n + 1));
    (n > 0).then(|| sum / n as f64)
}

/// `of / against − 1`, the relative gain; `None` when `against` is not positive.
pub fn gain(of: f64, against: f64) -> Option<f64> {
    (against > 0.0).then(|| of / against - 1.0)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn medians_means_and_gains() {
        assert_eq!(median([3.0, 1.0, 2.0]), Some(2.0));
        assert_eq!(median([4.0, 1.0, 3.0, 2.0]), Some(2.5));
        assert_eq!(median([f64::NAN, 1.0]), Some(1.0));
        assert_eq!(median(Vec::new()), None);
        assert_eq!(mean([1.0, 2.0]), Some(1.5));
        assert_eq!(mean(Vec::new()), None);
        assert_eq!(gain(175.0, 100.0), Some(0.75));
        assert_eq!(gain(1.0, 0.0), None);
    }
}
