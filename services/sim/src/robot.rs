//! A robot: where it is (and, for roam's unicycle, which way it faces), its own random
//! stream, and paper 002's motion model (Eq. 1) with a top speed and collisions. The
//! unicycle's rule is in [`crate::unicycle`]; both end in the same collision walk.

use rand_chacha::ChaCha8Rng;
use roam_world::scenario::MotionSpec;

use crate::event::Event;
use crate::translate::translate;
pub use crate::translate::Moved;
use crate::world::World;
use roam_world::noise;

/// A robot in the sim: a point that moves on the plane (paper 002 models no heading),
/// with a heading that only the unicycle model turns and uses.
#[derive(Debug, Clone)]
pub struct Robot {
    name: String,
    start: [f64; 2],
    at: [f64; 2],
    /// Heading at the start and now, radians counter-clockwise from +x, in [-π, π).
    start_heading: f64,
    heading: f64,
    /// The robot's own stream: its transition noise and its range noise.
    rng: ChaCha8Rng,
    /// Events that happened between steps (a reset put it on a free cell), reported
    /// with the next step.
    pub(crate) pending: Vec<Event>,
}

impl Robot {
    /// A robot at its start, facing `heading` (radians), its stream derived from the
    /// sim's seed and its name.
    pub(crate) fn new(name: &str, start: [f64; 2], heading: f64, seed: u64) -> Robot {
        let heading = crate::unicycle::wrap(heading);
        Robot {
            name: name.to_owned(),
            start,
            at: start,
            start_heading: heading,
            heading,
            rng: stream(seed, name),
            pending: Vec::new(),
        }
    }

    /// Back to its start (and its start heading) with its stream restarted from `seed`.
    pub(crate) fn reset(&mut self, seed: u64) {
        self.at = self.start;
        self.heading = self.start_heading;
        self.rng = stream(seed, &self.name);
        self.pending.clear();
    }

    /// Put back where a snapshot saw it at `step`, its stream restarted from
    /// `(seed, name, step)` (see [`crate::snapshot`]).
    pub(crate) fn resume(&mut self, pose: Resumed, seed: u64, step: u64) {
        self.start = pose.start;
        self.at = pose.at;
        self.start_heading = crate::unicycle::wrap(pose.start_heading);
        self.heading = crate::unicycle::wrap(pose.heading);
        self.rng = noise::stream(seed, &format!("robot/{}/resumed/{step}", self.name));
        self.pending.clear();
    }

    pub fn name(&self) -> &str {
        &self.name
    }

    /// Where it started (and returns to on a reset), world metres.
    pub fn start(&self) -> [f64; 2] {
        self.start
    }

    /// Where it is: the ground truth, world metres.
    pub fn position(&self) -> [f64; 2] {
        self.at
    }

    pub(crate) fn set_position(&mut self, at: [f64; 2]) {
        self.at = at;
    }

    /// Which way it faces: the ground truth, radians counter-clockwise from +x, in
    /// [-π, π). A point robot keeps its start heading (it has none that matters).
    pub fn heading_rad(&self) -> f64 {
        self.heading
    }

    /// Its heading at the start (and after a reset), radians.
    pub fn start_heading_rad(&self) -> f64 {
        self.start_heading
    }

    pub(crate) fn set_heading(&mut self, heading: f64) {
        self.heading = heading;
    }

    pub(crate) fn rng(&mut self) -> &mut ChaCha8Rng {
        &mut self.rng
    }
}

/// Where a snapshot saw a robot: its start and position, and its headings there.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Resumed {
    pub start: [f64; 2],
    pub at: [f64; 2],
    pub start_heading: f64,
    pub heading: f64,
}

/// The robot's stream: `"robot/<name>"` under the sim's seed.
fn stream(seed: u64, name: &str) -> ChaCha8Rng {
    noise::stream(seed, &format!("robot/{name}"))
}

/// Paper 002 Eq. 1, `p ← p + μ·u + ν`, for a robot at `at` given command `u` and the
/// transition noise `nu` already drawn, against the world as it is now.
///
/// - **Top speed.** The commanded move μ·u is clipped to `max_speed_m_per_step` (its
///   direction kept) before the noise is added; the event says by how much.
/// - **No command, no noise.** A zero command leaves the robot where it is: ν models
///   the drive's error, which a drive at rest does not make. (The caller draws ν every
///   step anyway, so a robot's stream does not depend on when it was commanded.)
/// - **Collisions.** The robot is a point and never enters a cell it may not be in
///   (a wall, an unknown cell, a block, a walker, off the map). The move, noise
///   included, is walked cell by cell along the straight segment; at the first such
///   cell the robot stops just short of it and a `Collision` event names the cell and
///   what is in it. Robots are not obstacles to each other (paper 002's robots are
///   points that share the plane).
pub fn step_motion(
    at: [f64; 2],
    u: [f64; 2],
    nu: [f64; 2],
    motion: &MotionSpec,
    world: &World,
) -> Moved {
    let mut events = Vec::new();
    if u == [0.0, 0.0] {
        return Moved { at, events };
    }
    let mut step = [motion.step_mu * u[0], motion.step_mu * u[1]];
    let length = step[0].hypot(step[1]);
    if length > motion.max_speed_m_per_step {
        let scale = motion.max_speed_m_per_step / length;
        step = [step[0] * scale, step[1] * scale];
        events.push(Event::SpeedClipped {
            requested_m: length,
            allowed_m: motion.max_speed_m_per_step,
        });
    }
    translate(at, step, nu, world, events)
}
