//! A robot's true path in one run, kept for the figures.

use serde::Serialize;

use crate::closed_loop::episode::Episode;
use roam_controller::weights::Scheme;

/// A robot's true path in one run, for the figures.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Trajectory {
    pub scheme: Scheme,
    pub z_is: f64,
    pub robot: String,
    pub success: bool,
    pub truth: Vec<[f64; 2]>,
}

impl Trajectory {
    pub(crate) fn of(scheme: Scheme, z_is: f64, episode: &Episode) -> Vec<Trajectory> {
        episode
            .robots
            .iter()
            .map(|r| Trajectory {
                scheme,
                z_is,
                robot: r.robot.clone(),
                success: r.success,
                truth: r.truth.clone(),
            })
            .collect()
    }
}
