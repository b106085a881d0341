//! One move against the world as it is now, cell by cell, stopping short of the first
//! cell the robot may not be in: where both motion models (paper 002's point,
//! `robot.rs`, and the unicycle, `unicycle.rs`) end.

use serde::Serialize;

use crate::event::Event;
use crate::raster;
use crate::world::World;

/// How far (in cells) a clipped move stops short of the cell it would have entered:
/// enough that rounding never puts the stopping point inside that cell.
const BACKOFF_CELLS: f64 = 1e-6;

/// The result of one move.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Moved {
    /// Where the robot ends, world metres.
    pub at: [f64; 2],
    /// What happened on the way (speed clipped, collision).
    pub events: Vec<Event>,
}

/// Moves a robot at `at` by `step + nu` against the world as it is now, walking the
/// segment cell by cell and stopping just short of the first cell it may not be in (a
/// `Collision` event, after `events`).
pub(crate) fn translate(
    at: [f64; 2],
    step: [f64; 2],
    nu: [f64; 2],
    world: &World,
    mut events: Vec<Event>,
) -> Moved {
    let target = [at[0] + step[0] + nu[0], at[1] + step[1] + nu[1]];
    let (from, to) = (world.to_cell_units(at), world.to_cell_units(target));
    let Some((t, cell)) = raster::first_blocked(from, to, |c| world.is_blocked(c)) else {
        return Moved { at: target, events };
    };
    let cells_long = (to[0] - from[0]).hypot(to[1] - from[1]);
    let t_stop = (t - BACKOFF_CELLS / cells_long.max(f64::MIN_POSITIVE)).max(0.0);
    let mut stopped = [
        at[0] + (target[0] - at[0]) * t_stop,
        at[1] + (target[1] - at[1]) * t_stop,
    ];
    // The stopping point must be on a free cell; rounding could still tip it over the
    // edge of a tiny last step, and then the robot simply stays put.
    if world.cell_of(stopped).is_none_or(|c| world.is_blocked(c)) {
        stopped = at;
    }
    events.push(Event::Collision {
        target,
        stopped_at: stopped,
        cell: [cell.0, cell.1],
        obstacle: world
            .obstacle_at(cell)
            .unwrap_or(crate::world::Obstacle::Wall),
    });
    Moved {
        at: stopped,
        events,
    }
}
