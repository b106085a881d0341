//! The change coupling: paper 004's change map folded into paper 000's information map.
//!
//! Neither paper joins the two; this is roam's rule. A planner configured with a
//! `change_layer` (the mapper's `change_information`: round(100 · P_c(E > 0)), paper
//! 004 Eq. 2, as u8 scores) plans on
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

use roam_proto::cells::Cells;
use roam_proto::map::Layer;

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
