//! What one observation did to the map, and the counts over the whole map.

use serde::Serialize;

/// What one observation did to the map.
#[derive(Debug, Clone, PartialEq, Default, Serialize)]
pub struct Update {
    /// The observation's time, seconds.
    pub t: f64,
    /// Cells seen in the window.
    pub observed: u32,
    /// Cells seen free where the map had them occupied, or the reverse.
    pub flipped: Vec<(u32, u32)>,
    /// Cells seen for the first time.
    pub discovered: Vec<(u32, u32)>,
    /// Poisson events recorded (flips that count as events, see [`crate::poisson`]).
    pub events: u32,
}

impl Update {
    /// The number of map changes: flips, and discoveries too if `count_discoveries`.
    pub fn map_changes(&self, count_discoveries: bool) -> usize {
        self.flipped.len()
            + if count_discoveries {
                self.discovered.len()
            } else {
                0
            }
    }

    /// The changed cells: flips, then discoveries if `count_discoveries`.
    pub fn changed(&self, count_discoveries: bool) -> impl Iterator<Item = (u32, u32)> + '_ {
        let discovered: &[(u32, u32)] = if count_discoveries {
            &self.discovered
        } else {
            &[]
        };
        self.flipped.iter().chain(discovered).copied()
    }

    /// The centroid of the changed cells, rounded to a cell (§2's local exploration
    /// goal); `None` when nothing changed.
    pub fn centroid(&self, count_discoveries: bool) -> Option<(u32, u32)> {
        let (mut n, mut sx, mut sy) = (0u64, 0u64, 0u64);
        for (x, y) in self.changed(count_discoveries) {
            n += 1;
            sx += u64::from(x);
            sy += u64::from(y);
        }
        if n == 0 {
            return None;
        }
        let round = |s: u64| ((s as f64 / n as f64).round() as u64).min(u64::from(u32::MAX)) as u32;
        Some((round(sx), round(sy)))
    }

    /// Folds another update of the same map into this one (several robots' windows of
    /// one instant); the time is the later one's.
    pub fn merge(&mut self, other: Update) {
        self.t = self.t.max(other.t);
        self.observed = self.observed.saturating_add(other.observed);
        self.flipped.extend(other.flipped);
        self.discovered.extend(other.discovered);
        self.events = self.events.saturating_add(other.events);
    }
}

/// Counts over the whole map.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize)]
pub struct MapStats {
    /// Cells seen at least once.
    pub seen_cells: u64,
    /// Cells with at least one event (a rate above zero).
    pub active_cells: u64,
    /// Poisson events recorded since the start.
    pub events: u64,
    /// Observations taken.
    pub observations: u64,
}
