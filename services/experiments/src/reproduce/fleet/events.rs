//! The news itself: every object that lands in or leaves the warehouse is a change
//! event, and the fleet notices it when a robot first sees one of its cells afterwards
//! (its observation window holds the cell, seen, in its new state). The detection
//! latency is the time between the two: what the fleet's week is measured by.

use std::collections::BTreeMap;

use roam_proto::cells::Cells;
use roam_proto::sim::{LocalObservation, ObjectTruth};
use serde::Serialize;

/// An object landed or left.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum ChangeKind {
    Appeared,
    Vanished,
}

/// One change and when the fleet saw it.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ChangeEvent {
    pub object: u64,
    pub zone: usize,
    pub kind: ChangeKind,
    pub at_s: f64,
    /// When a robot first saw one of its cells afterwards; `None`: not by the run's end.
    pub seen_s: Option<f64>,
    /// The footprint's map cells: x0, y0, x1, y1 inclusive.
    #[serde(skip)]
    bounds: [i64; 4],
}

impl ChangeEvent {
    /// Seconds from the change to its sighting, if it was seen.
    pub fn latency_s(&self) -> Option<f64> {
        self.seen_s.map(|s| s - self.at_s)
    }

    /// The footprint's map cells: x0, y0, x1, y1 inclusive.
    pub fn bounds(&self) -> [i64; 4] {
        self.bounds
    }
}

/// Every change of a run, and the ones not yet seen.
#[derive(Debug, Default)]
pub struct ChangeLog {
    events: Vec<ChangeEvent>,
    /// Indices of the events not seen yet.
    open: Vec<usize>,
    /// The objects landed at the last update: id → (zone, bounds).
    landed: BTreeMap<u64, (usize, [i64; 4])>,
}

impl ChangeLog {
    pub fn events(&self) -> &[ChangeEvent] {
        &self.events
    }

    /// The objects now (the sim's); each that landed or left since the last update is
    /// an event at `t`.
    pub fn update(&mut self, landed: &[ObjectTruth], t: f64) {
        let now: BTreeMap<u64, (usize, [i64; 4])> = landed
            .iter()
            .map(|o| (o.id, (o.zone as usize, o.cells)))
            .collect();
        for (id, &(zone, bounds)) in &now {
            if !self.landed.contains_key(id) {
                self.push(*id, zone, ChangeKind::Appeared, t, bounds);
            }
        }
        let gone: Vec<(u64, (usize, [i64; 4]))> = self
            .landed
            .iter()
            .filter(|(id, _)| !now.contains_key(id))
            .map(|(&id, &v)| (id, v))
            .collect();
        for (id, (zone, bounds)) in gone {
            self.push(id, zone, ChangeKind::Vanished, t, bounds);
        }
        self.landed = now;
    }

    fn push(&mut self, object: u64, zone: usize, kind: ChangeKind, at_s: f64, bounds: [i64; 4]) {
        self.open.push(self.events.len());
        self.events.push(ChangeEvent {
            object,
            zone,
            kind,
            at_s,
            seen_s: None,
            bounds,
        });
    }

    /// A robot's observation at `t`: every open event one of whose cells it saw is seen.
    pub fn observe(&mut self, o: &LocalObservation, t: f64) {
        let Cells::I8(cells) = &o.cells else {
            return;
        };
        let (x0, y0) = (i64::from(o.x0), i64::from(o.y0));
        let (w, h) = (i64::from(o.meta.width), i64::from(o.meta.height));
        let events = &mut self.events;
        self.open.retain(|&i| {
            let e = &mut events[i];
            if e.at_s > t {
                return true;
            }
            let [ex0, ey0, ex1, ey1] = e.bounds;
            let (ix0, iy0) = (ex0.max(x0), ey0.max(y0));
            let (ix1, iy1) = (ex1.min(x0 + w - 1), ey1.min(y0 + h - 1));
            for y in iy0..=iy1 {
                for x in ix0..=ix1 {
                    let i = ((y - y0) * w + (x - x0)) as usize;
                    if cells.get(i).is_some_and(|&v| v >= 0) {
                        e.seen_s = Some(t);
                        return false;
                    }
                }
            }
            true
        });
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use roam_proto::map::{GridMeta, Origin};
    use roam_sim::semi_static::{landed_truth, SemiStatic};
    use roam_sim::world::Footprint;

    fn object(id: u64, centre: (i64, i64)) -> Vec<ObjectTruth> {
        landed_truth(&[SemiStatic {
            id,
            zone: 0,
            centre,
            footprint: Footprint {
                width_cells: 3,
                height_cells: 3,
            },
            stay_steps: 10,
            landed_step: Some(1),
        }])
    }

    fn window(x0: u32, y0: u32, seen: bool) -> LocalObservation {
        LocalObservation {
            robot: "r1".into(),
            step: 1,
            time_s: 0.0,
            at: [0.0, 0.0],
            x0,
            y0,
            meta: GridMeta {
                width: 4,
                height: 4,
                resolution: 0.05,
                origin: Origin::default(),
            },
            cells: Cells::I8(vec![if seen { 0 } else { -1 }; 16]),
        }
    }

    #[test]
    fn a_change_is_seen_when_a_window_shows_one_of_its_cells() {
        let mut log = ChangeLog::default();
        log.update(&object(7, (10, 10)), 5.0);
        assert_eq!(log.events().len(), 1);
        assert_eq!(log.events()[0].kind, ChangeKind::Appeared);
        // A window elsewhere, then one over its cells that saw nothing, then one that did.
        log.observe(&window(0, 0, true), 6.0);
        log.observe(&window(8, 8, false), 7.0);
        assert_eq!(log.events()[0].seen_s, None);
        log.observe(&window(8, 8, true), 9.0);
        assert_eq!(log.events()[0].latency_s(), Some(4.0));
        // It leaves: a second event, seen later.
        log.update(&[], 20.0);
        assert_eq!(log.events()[1].kind, ChangeKind::Vanished);
        log.observe(&window(11, 11, true), 25.0);
        assert_eq!(log.events()[1].latency_s(), Some(5.0));
    }
}
