//! A sensor window: a rectangle of the map and the ROS values seen in it.

use roam_world::observation::Observation;

/// A seen value at or above this is occupied, below it free.
pub const OCCUPIED_FROM: i8 = 50;

/// A sensor window: a rectangle of the map and what was seen in it.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct ObservationWindow<'a> {
    /// The map cell at the window's lower-left corner.
    pub x0: u32,
    pub y0: u32,
    pub width: u32,
    pub height: u32,
    /// Row-major from (x0, y0): -1 not seen, 0..=100 seen (see [`crate::change_map`]).
    pub cells: &'a [i8],
}

impl<'a> From<&'a Observation> for ObservationWindow<'a> {
    fn from(o: &'a Observation) -> Self {
        ObservationWindow {
            x0: o.x0,
            y0: o.y0,
            width: o.width,
            height: o.height,
            cells: &o.cells,
        }
    }
}

impl<'a> ObservationWindow<'a> {
    /// The window of a sim observation from the wire (`sim/observation`), or `None`
    /// when its cells are not i8 occupancy values. (Its fit to the map is the
    /// mapper's check; [`ChangeMap::observe`](crate::change_map::ChangeMap::observe)
    /// refuses a window that does not fit.)
    pub fn from_wire(o: &'a roam_proto::sim::LocalObservation) -> Option<Self> {
        let roam_proto::cells::Cells::I8(cells) = &o.cells else {
            return None;
        };
        Some(ObservationWindow {
            x0: o.x0,
            y0: o.y0,
            width: o.meta.width,
            height: o.meta.height,
            cells,
        })
    }
}
