//! Where the fleet's robots start on the built-in world, and their missions.

use crate::BenchError;
use roam_proto::controller::Mission;

/// What the robots are: where each starts and its mission, the last one the joiner.
pub(super) struct Fleet {
    pub(super) places: Vec<[f64; 2]>,
}

impl Fleet {
    pub(super) fn name(k: usize) -> String {
        format!("fleet-{k}")
    }

    /// Robot `k`'s mission: to the robot half the fleet away and back.
    pub(super) fn mission(&self, k: usize) -> Mission {
        let n = self.places.len();
        Mission {
            after_step: None,
            robot: Fleet::name(k),
            id: format!("bench-{k}"),
            waypoints: vec![self.places[(k + n / 2) % n], self.places[k]],
            recovery: false,
        }
    }
}

/// `robots` places on free cells (every 8-neighbour free too) spread over the built-in
/// world, and its own robots' names (they leave the sim first).
pub(super) fn places(robots: usize) -> Result<(Fleet, Vec<String>), BenchError> {
    let (places, own) = crate::spread::spread(robots, true)?;
    Ok((Fleet { places }, own))
}
