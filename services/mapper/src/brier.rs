//! The Brier score of a belief against the truth, for scoring the map now
//! ([`crate::belief`]) in batch: the mean of (p − o)² over the cells scored, p the
//! believed probability that a cell is occupied and o 1 where it truly is, 0 where not
//! (Brier 1950). 0 is a perfect map, 0.25 a map that says 1/2 everywhere, 1 a map
//! certain and wrong everywhere.

use crate::error::MapperError;

/// A cell's believed probability of being occupied, as the layers hold it.
pub trait Probability: Copy {
    /// The probability in 0..=1, or `None` when the value is no belief.
    fn probability(self) -> Option<f64>;
}

/// Probabilities 0..=1 (clamped); NaN is no belief.
impl Probability for f64 {
    fn probability(self) -> Option<f64> {
        (!self.is_nan()).then(|| self.clamp(0.0, 1.0))
    }
}

/// Scores 0..=100 (the `news` and `change_information` form; above 100 as 100).
impl Probability for u8 {
    fn probability(self) -> Option<f64> {
        Some(f64::from(self.min(100)) / 100.0)
    }
}

/// ROS occupancy 0..=100 (the `occupied_now` layer); -1 (unknown) is no belief.
impl Probability for i8 {
    fn probability(self) -> Option<f64> {
        (self >= 0).then(|| f64::from(self.min(100)) / 100.0)
    }
}

/// The Brier score of `belief` against `truth` (occupied or not, one per cell, the same
/// length) over the cell indices `cells` (a cell listed twice counts twice). Refused: the
/// lengths differ, an index is off the grid, no cell is listed, or a listed cell holds
/// no belief.
pub fn brier<P: Probability>(
    belief: &[P],
    truth: &[bool],
    cells: impl IntoIterator<Item = usize>,
) -> Result<f64, MapperError> {
    if belief.len() != truth.len() {
        return Err(MapperError::ScoreSizes {
            belief: belief.len(),
            truth: truth.len(),
        });
    }
    let (mut sum, mut n) = (0.0, 0u64);
    for index in cells {
        let (Some(&b), Some(&occupied)) = (belief.get(index), truth.get(index)) else {
            return Err(MapperError::ScoreCellOff {
                index,
                cells: belief.len(),
            });
        };
        let p = b.probability().ok_or(MapperError::NoBelief { index })?;
        let o = if occupied { 1.0 } else { 0.0 };
        sum += (p - o) * (p - o);
        n += 1;
    }
    if n == 0 {
        return Err(MapperError::ScoreEmpty);
    }
    Ok(sum / n as f64)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_brier_score_by_hand() {
        let truth = [true, false, true, false];
        let belief = [1.0, 0.0, 0.5, 0.25];
        // (0 + 0 + 0.25 + 0.0625) / 4.
        assert_eq!(brier(&belief, &truth, 0..4), Ok(0.078_125));
        // Only the cells asked for, twice if twice.
        assert_eq!(brier(&belief, &truth, [2, 2, 0]), Ok(0.5 / 3.0));
        // The same belief as u8 scores and as ROS occupancy.
        assert_eq!(brier(&[100u8, 0, 50, 25], &truth, 0..4), Ok(0.078_125));
        assert_eq!(brier(&[100i8, 0, 50, 25], &truth, 0..4), Ok(0.078_125));
        // Certain and wrong.
        assert_eq!(brier(&[0.0, 1.0], &[true, false], 0..2), Ok(1.0));
    }

    #[test]
    fn bad_input_is_refused() {
        let truth = [true, false];
        assert_eq!(
            brier(&[0.5], &truth, 0..1),
            Err(MapperError::ScoreSizes {
                belief: 1,
                truth: 2
            })
        );
        assert_eq!(
            brier(&[0.5, 0.5], &truth, [0, 2]),
            Err(MapperError::ScoreCellOff { index: 2, cells: 2 })
        );
        assert_eq!(brier(&[0.5, 0.5], &truth, []), Err(MapperError::ScoreEmpty));
        assert_eq!(
            brier(&[0.5, f64::NAN], &truth, 0..2),
            Err(MapperError::NoBelief { index: 1 })
        );
        assert_eq!(
            brier(&[-1i8, 0], &truth, 0..2),
            Err(MapperError::NoBelief { index: 0 })
        );
    }
}
