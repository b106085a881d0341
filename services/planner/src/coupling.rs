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
//! w_xy  = ε + (1 − ε) · N_xy / 100                      (N_xy = round(100 · P_news))
//! I'_xy = round(I_xy · w_xy · max(I) / max(I · w))
//! ```
//!
//! interest × the probability that there is news: what a look at the cell is expected to
//! find that the fleet does not know, scaled so that the best news on the map is worth
//! the best interest. ε is the **news floor** (`news_floor`, default
//! [`DEFAULT_NEWS_FLOOR`]): the share of its interest a cell keeps however recently it
//! was seen. Where nothing was seen, I' = I; a cell of no interest stays at 0 however
//! much it changes (what is worth a look is the operator's information map; the news
//! only weighs it). The product cannot leave paper 000's 0–100 scale (I' ≤ max I), and
//! it needs no "early in the day" escape as the maximum does: the news value's prior
//! makes every cell news as time passes unseen, so the map never goes dark. Pair it with
//! the `news` layer, not with `change_information`, which is 0 wherever no event was
//! seen.
//!
//! **Why a floor** (roam's choice; measured in `roam reproduce fleet`, seed 0, one
//! shift). With ε = 0 a cell just seen, or on another robot's plan, is worth nothing:
//! the planner then threads its route between the fleet's recent looks, drives a median
//! 0.29 of each window and detected changes in a median 489 s, worse than ten robots
//! planning on the static map alone (`independent`, 0.70 of each window). With ε = 0.25
//! a look at a just-seen cell still counts for a quarter of its interest, so the news
//! decides where a robot goes first without making the rest of the map a wall of zeros:
//! the fleet drove 0.64 of each window, detected in a median 144 s, and its belief's
//! Brier score fell from 0.0140 to 0.0084, with no window late.
//!
//! **Why scaled** (the parameter of the rule: the scale is the map's own best news; the
//! choice is roam's). Unscaled, I · N / 100 shrinks as the fleet keeps looking: an hour
//! into a warehouse shift most news is a few percent, the map a few points out of 100,
//! while the planner's other terms (the PEB cost W_loc, the idle term) keep their
//! weight. Measured in `roam reproduce fleet`: the greedy planner then found every detour
//! worth less than its PEB cost and planned the fastest path, and the fleet drove a
//! median 0.29 of each window. The planner's choice *among* cells depends only on the
//! ratios of I · N, which the scale keeps; what it changes is that a fleet in downtime,
//! which gains nothing by waiting, still goes where the news is most likely.

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
    /// I' = round(I · w · max(I) / max(I · w)), w = ε + (1 − ε) · N / 100, N the news
    /// scores and ε the news floor ([`news_product`]).
    News,
}

/// The news floor ε by default (module doc: why a floor).
pub const DEFAULT_NEWS_FLOOR: f64 = 0.25;

/// The config key of the news floor, named in its errors.
pub const NEWS_FLOOR_NAME: &str = "news_floor";

/// Whether `floor` is a news floor the coupling takes: a share, 0 to 1.
pub fn is_news_floor(floor: f64) -> bool {
    floor.is_finite() && (0.0..=1.0).contains(&floor)
}

impl Coupling {
    /// The coupled information map; `change` as long as `information`; `news_floor`
    /// the news product's ε (unused by `max`).
    pub fn apply(self, information: &[u8], change: &[u8], news_floor: f64) -> Vec<u8> {
        match self {
            Coupling::Max => couple(information, change),
            Coupling::News => news_product(information, change, news_floor),
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

/// I'_xy = round(I_xy · w_xy · max(I) / max(I · w)), w_xy = ε + (1 − ε) · N_xy / 100,
/// cell by cell (module doc): the news product with the news floor ε = `floor`, scaled
/// so that the best news on the map is worth the best interest; N above 100 taken as
/// 100; `news` as long as `information`. All 0 when there is no news (ε = 0 and N = 0
/// everywhere).
///
/// Exact in integers: ε is taken in thousandths (f = round(1000 · ε), clamped to
/// 0..=1000, so 0.25 is exactly 250), w in units of 1/100,000, and the scaling rounds
/// halves up, so the same maps give the same scores on every machine.
pub fn news_product(information: &[u8], news: &[u8], floor: f64) -> Vec<u8> {
    let floor_thousandths = if floor.is_finite() {
        (floor.clamp(0.0, 1.0) * 1000.0).round() as u32
    } else {
        0
    };
    let products: Vec<u64> = information
        .iter()
        .zip(news)
        .map(|(&i, &n)| {
            let weight =
                floor_thousandths * 100 + (1000 - floor_thousandths) * u32::from(n.min(100));
            u64::from(i) * u64::from(weight)
        })
        .collect();
    let top_product = products.iter().copied().max().unwrap_or(0);
    let top_interest = information
        .iter()
        .take(products.len())
        .map(|&i| u64::from(i))
        .max()
        .unwrap_or(0);
    if top_product == 0 {
        return vec![0; products.len()];
    }
    products
        .iter()
        .map(|&p| {
            // Halves rounded up; at most top_interest, so within u8. p ≤ 255 · 100,000,
            // so the product with top_interest stays far inside u64.
            let scaled = (p * top_interest * 2 + top_product) / (2 * top_product);
            u8::try_from(scaled).unwrap_or(u8::MAX)
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
    fn without_a_floor_the_news_product_is_interest_times_the_probability_of_news_scaled_to_the_best(
    ) {
        // All news: the interest itself.
        assert_eq!(
            news_product(&[80, 40, 0, 10], &[100; 4], 0.0),
            vec![80, 40, 0, 10]
        );
        // Interest 80 at N 0, 50, 100; 0 stays 0; 55 × 50 → 27.5 rounds up; N above
        // 100 counts as 100.
        assert_eq!(
            news_product(&[80, 80, 80, 0, 55, 40], &[0, 50, 100, 100, 50, 255], 0.0),
            vec![0, 40, 80, 0, 28, 40]
        );
        // Little news anywhere (the fleet looked everywhere lately): the best of it is
        // worth the best interest, the rest in proportion, so the planner's trade-offs
        // (the PEB cost, the idle term) meet the same scale as on the static map.
        assert_eq!(
            news_product(&[80, 40, 40, 10], &[2, 4, 1, 0], 0.0),
            vec![80, 80, 20, 0]
        );
        assert_eq!(news_product(&[80, 40], &[0, 0], 0.0), vec![0, 0]);
        assert_eq!(
            Coupling::News.apply(&[80, 30], &[25, 100], 0.0),
            vec![53, 80]
        );
        assert_eq!(
            Coupling::Max.apply(&[80, 30], &[25, 100], 0.5),
            vec![80, 100]
        );
        assert_eq!(Coupling::default(), Coupling::Max);
    }

    #[test]
    fn the_news_floor_keeps_a_share_of_a_just_seen_cells_interest() {
        // ε = 0.25: N 0, 50, 100 weigh 0.25, 0.625, 1.
        assert_eq!(
            news_product(&[80, 80, 80, 0], &[0, 50, 100, 100], 0.25),
            vec![20, 50, 80, 0]
        );
        // No news anywhere: the interest scaled by the floor alone, so the map keeps
        // its shape.
        assert_eq!(news_product(&[80, 40], &[0, 0], 0.25), vec![80, 40]);
        // ε = 1: the news is ignored; out-of-range floors are taken at the nearest end.
        assert_eq!(news_product(&[80, 40], &[0, 100], 1.0), vec![80, 40]);
        assert_eq!(news_product(&[80, 40], &[0, 100], 7.0), vec![80, 40]);
        // Below 0 (or not a number) is no floor: the only news, worth 40 · 100, is worth
        // the best interest.
        assert_eq!(news_product(&[80, 40], &[0, 100], -1.0), vec![0, 80]);
        assert_eq!(news_product(&[80, 40], &[0, 100], f64::NAN), vec![0, 80]);
        assert!(is_news_floor(DEFAULT_NEWS_FLOOR));
        assert!(!is_news_floor(1.5) && !is_news_floor(f64::NAN) && !is_news_floor(-0.1));
    }

    #[test]
    fn the_news_product_never_passes_the_best_interest_and_keeps_the_order_of_interest_times_weight(
    ) {
        // Exhaustively on two cells, at three floors: the best product at the best
        // interest, every cell at its exact ratio rounded half up.
        for floor_thousandths in [0u32, 250, 600] {
            let floor = f64::from(floor_thousandths) / 1000.0;
            for i in (0..=200u8).step_by(5) {
                for n in 0..=100u8 {
                    let got = news_product(&[i, 200], &[n, 1], floor);
                    let weight =
                        |n: u8| floor_thousandths * 100 + (1000 - floor_thousandths) * u32::from(n);
                    let (a, b) = (u32::from(i) * weight(n), 200 * weight(1));
                    let top = a.max(b);
                    let want = |p: u32| (f64::from(p) * 200.0 / f64::from(top)).round();
                    assert_eq!(f64::from(got[0]), want(a), "ε {floor}, I {i}, N {n}");
                    assert_eq!(f64::from(got[1]), want(b), "ε {floor}, I {i}, N {n}");
                    assert!(got[0].max(got[1]) == 200);
                }
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
