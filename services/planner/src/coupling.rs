//! The change coupling: paper 004's change map folded into paper 000's information map.
//!
//! Neither paper joins the two; these are roam's rules, chosen by the planner config's
//! `coupling` ([`Coupling`]).
//!
//! **`max`** (the default). A planner configured with a `change_layer` (the mapper's
//! `change_information`: round(100 · P_c(E > 0)), paper 004 Eq. 2, as u8 scores) plans on
//!
//! ```text
//! I'_xy = max(I_xy, C_xy)
//! ```
//!
//! cell by cell, I_xy the static information map and C_xy the change score. The maximum
//! and not the change layer alone: early in a day the mapper has seen little change and
//! its layer is zero almost everywhere, and a planner on it alone would have nothing to
//! be curious about; the sum would push zones that are both informative and changing
//! past paper 000's 0–100 scale (Model I indexes its counts by score). With the maximum
//! a cell where the world was seen to change is worth at least what its probability of
//! having changed since earns, and every other cell keeps its static score, so Eqs. 3
//! and 8–11 keep their meaning on the coupled map.
//!
//! **`news`**, the news product, for a fleet. With the mapper's `news` layer as the change
//! layer (round(100 · P_news), the probability that a cell changed since any robot last
//! saw it or will see it on its current mission, `roam_mapper::news`) the planner plans
//! on
//!
//! ```text
//! I'_xy = round(I_xy · N_xy / 100)        (N_xy = round(100 · P_news))
//! ```
//!
//! interest × the probability that there is news: what a look at the cell is expected to
//! find that the fleet does not know. A cell just seen, or on another robot's plan, is
//! worth nothing however interesting; a cell nobody has seen for long is worth its whole
//! static score; a cell of no interest stays at 0 however much it changes (what is
//! worth a look is the operator's information map; the news only discounts it). The
//! product cannot leave paper 000's 0–100 scale (I' ≤ I), and it needs no "early in the
//! day" escape as the maximum does: the news value's prior makes every cell news as time
//! passes unseen, so the map never goes dark. Pair it with the `news` layer, not with
//! `change_information`, which is 0 wherever no event was seen.

use roam_proto::cells::Cells;
use roam_proto::map::Layer;
use serde::{Deserialize, Serialize};

/// How the change layer is folded into the information map (module doc).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Coupling {
    /// I' = max(I, C) (default).
    #[default]
    Max,
    /// I' = round(I · N / 100), N the news scores.
    News,
}

impl Coupling {
    /// The coupled information map; `change` as long as `information`.
    pub fn apply(self, information: &[u8], change: &[u8]) -> Vec<u8> {
        match self {
            Coupling::Max => couple(information, change),
            Coupling::News => news_product(information, change),
        }
    }

    pub fn as_str(self) -> &'static str {
        match self {
            Coupling::Max => "max",
            Coupling::News => "news",
        }
    }
}

/// The change layer, when it can be coupled into `information`: u8 cells on the same
/// grid (size, resolution and origin).
pub fn usable<'a>(change: &'a Layer, information: &Layer) -> Option<&'a Layer> {
    let same_grid = change.meta == information.meta;
    let scores =
        matches!(&change.cells, Cells::U8(cells) if cells.len() == information.cells.len());
    (same_grid && scores).then_some(change)
}

/// I'_xy = max(I_xy, C_xy) cell by cell (module doc); `change` as long as `information`.
pub fn couple(information: &[u8], change: &[u8]) -> Vec<u8> {
    information
        .iter()
        .zip(change)
        .map(|(&i, &c)| i.max(c))
        .collect()
}

/// I'_xy = round(I_xy · N_xy / 100) cell by cell (module doc), N above 100 taken as 100;
/// `news` as long as `information`.
pub fn news_product(information: &[u8], news: &[u8]) -> Vec<u8> {
    information
        .iter()
        .zip(news)
        .map(|(&i, &n)| {
            // Exact in integers, halves rounded up; at most i, so within u8.
            let product = (u32::from(i) * u32::from(n.min(100)) + 50) / 100;
            u8::try_from(product).unwrap_or(u8::MAX)
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::maps::tests::layer;

    #[test]
    fn a_changed_cell_is_worth_at_least_its_change_and_the_rest_keeps_its_score() {
        assert_eq!(
            couple(&[0, 30, 80, 100], &[50, 0, 90, 20]),
            vec![50, 30, 90, 100]
        );
    }

    #[test]
    fn the_news_product_is_interest_times_the_probability_of_news() {
        // Interest 80 at P_news 0, 0.5, 1; 0 stays 0; 55 × 0.5 = 27.5 rounds up; news
        // scores above 100 count as 100; an information score above 100 keeps its scale.
        assert_eq!(
            news_product(
                &[80, 80, 80, 0, 55, 40, 200],
                &[0, 50, 100, 100, 50, 255, 50]
            ),
            vec![0, 40, 80, 0, 28, 40, 100]
        );
        assert_eq!(Coupling::News.apply(&[80, 30], &[25, 100]), vec![20, 30]);
        assert_eq!(Coupling::Max.apply(&[80, 30], &[25, 100]), vec![80, 100]);
        assert_eq!(Coupling::default(), Coupling::Max);
        // Exhaustively: never above the interest, and round(I · N / 100).
        for i in 0..=255u8 {
            for n in 0..=100u8 {
                let got = news_product(&[i], &[n])[0];
                let want = (f64::from(i) * f64::from(n) / 100.0).round();
                assert_eq!(f64::from(got), want, "I {i}, N {n}");
                assert!(got <= i);
            }
        }
    }

    #[test]
    fn only_a_u8_layer_on_the_same_grid_is_coupled() {
        let info = layer("information", 1, Cells::U8(vec![1, 2, 3]));
        let change = layer("change_information", 1, Cells::U8(vec![0, 0, 9]));
        assert!(usable(&change, &info).is_some());
        let wider = layer("change_information", 1, Cells::U8(vec![0; 4]));
        assert!(usable(&wider, &info).is_none());
        let floats = layer("change_information", 1, Cells::F32(vec![0.0; 3]));
        assert!(usable(&floats, &info).is_none());
    }
}
