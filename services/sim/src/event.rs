//! What happened to a robot during a step, besides its readings.

use serde::Serialize;

use crate::world::Obstacle;

/// One thing that happened to a robot in a step.
#[derive(Debug, Clone, PartialEq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Event {
    /// The commanded move μ·|u| was longer than the top speed and was shortened.
    SpeedClipped {
        /// The commanded move, metres.
        requested_m: f64,
        /// The top speed, metres per step.
        allowed_m: f64,
    },
    /// The move would have entered a cell the robot may not be in; the robot stopped
    /// just short of it.
    Collision {
        /// Where the move (noise included) would have ended, world metres.
        target: [f64; 2],
        /// Where the robot stopped, world metres.
        stopped_at: [f64; 2],
        /// The cell it would have entered (grid x, y; may be off the map).
        cell: [i64; 2],
        /// What is in that cell.
        obstacle: Obstacle,
    },
    /// A block or walker came onto the robot's cell (or a reset put the robot back on
    /// a start that a block now covers): the robot was put on the centre of the nearest
    /// free cell.
    Displaced {
        from: [f64; 2],
        to: [f64; 2],
        by: Obstacle,
    },
    /// Like `Displaced`, but no free cell is left on the map: the robot stays where it
    /// is, inside the obstacle.
    Trapped { by: Obstacle },
}
