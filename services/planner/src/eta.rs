//! The travel-time estimate of paper 000 Eq. 2:
//! `t_ETA = v_lin · Σ d_i + v_ang · Σ θ_i`.
//!
//! d_i is the distance between consecutive cell centres (one cell or √2 cells), θ_i the
//! absolute heading change between consecutive moves (a multiple of 45°). The first
//! move costs no turn: the robot's heading at the start is not known to the planner.

use crate::params::GaParams;
use crate::world::{Cell, World};

/// Seconds of one move of `dir` after a move of `prev_dir`.
#[inline]
pub fn step_time(world: &World, params: &GaParams, prev_dir: Option<usize>, dir: usize) -> f64 {
    step_time_at(world.meta.resolution, params, prev_dir, dir)
}

/// Seconds of one move of `dir` after a move of `prev_dir` on cells of `resolution`
/// metres (the fine map's, for the path the robot drives).
#[inline]
pub fn step_time_at(
    resolution: f64,
    params: &GaParams,
    prev_dir: Option<usize>,
    dir: usize,
) -> f64 {
    let cells = if dir % 2 == 1 {
        std::f64::consts::SQRT_2
    } else {
        1.0
    };
    let distance = cells * resolution;
    let turn = prev_dir.map_or(0.0, |p| {
        let diff = p.abs_diff(dir);
        diff.min(8 - diff) as f64 * std::f64::consts::FRAC_PI_4
    });
    params.v_lin * distance + params.v_ang * turn
}

/// t_ETA of a whole path (Eq. 2). A step between cells that are not neighbours (never
/// produced by the planner) is costed as a straight line with no turn.
pub fn path_eta(world: &World, params: &GaParams, path: &[Cell]) -> f64 {
    let mut t = 0.0;
    let mut prev = None;
    for pair in path.windows(2) {
        match world.direction(pair[0], pair[1]) {
            Some(dir) => {
                t += step_time(world, params, prev, dir);
                prev = Some(dir);
            }
            None => {
                let (ax, ay) = world.xy(pair[0]);
                let (bx, by) = world.xy(pair[1]);
                let cells =
                    ((ax as f64 - bx as f64).powi(2) + (ay as f64 - by as f64).powi(2)).sqrt();
                t += params.v_lin * cells * world.meta.resolution;
                prev = None;
            }
        }
    }
    t
}
