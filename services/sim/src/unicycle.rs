//! roam's unicycle: a robot with a heading that pays for turning (a differential-drive
//! robot), beside paper 002's holonomic point (Eq. 1, [`crate::robot::step_motion`]).
//!
//! Paper 002 has no such robot; it is roam's addition. Paper 000's time model, Eq. 2
//! (`t_ETA = v_lin·Σd + v_ang·Σθ`), charges every radian of heading change, and a point
//! robot never turns, so against a point robot only v_lin can ever be calibrated. A
//! scenario picks the model with `motion.model`.
//!
//! **The rule (rotate, then drive).** The command `u` is the same as the point robot's:
//! paper 002 Eq. 1's displacement command, asking for a move of μ·u this step. Each step
//! of `dt = time.step_s` seconds the unicycle
//!
//! 1. turns toward the command's direction ψ = atan2(u_y, u_x): the heading error
//!    e = wrap(ψ − φ) is closed by at most w_max·dt, taking |Δφ| / w_max seconds;
//! 2. drives straight along its new heading for the rest of the step, if it now faces ψ:
//!    forward = min(μ·|u|, v_max · (dt − |Δφ|/w_max)). When |e| ≥ w_max·dt the whole step
//!    is spent turning and the robot does not drive at all (a robot never drives
//!    sideways or backwards toward a command behind it);
//! 3. gets paper 002's transition noise ν ~ N(0, σ_tr²) per axis on its position, as
//!    the point robot does (the heading gets none), and collides as the point does: the
//!    move, noise included, is walked cell by cell and stops short of a blocked cell.
//!
//! A zero command leaves the robot as it is (no turn, no move, no noise), as for the
//! point. The top speed is the unicycle's own `v_max_m_per_s` (the point model's
//! `max_speed_m_per_step` does not apply); a command longer than v_max·dt is reported as
//! a clipped speed. The time spent turning is not.
//!
//! **What it implies for Eq. 2.** Turning and driving share each step's time, so a turn
//! of θ in place followed by a straight d takes θ/w_max + d/v_max seconds (up to the
//! last step's rounding): Eq. 2 with v_lin = 1/v_max s/m and v_ang = 1/w_max s/rad is
//! this robot's true time model when it turns in place at its corners. (A rule that
//! drives while turning, e.g. forward speed ∝ cos e, would make a 90° turn cost about a
//! third of (π/2)/w_max and Eq. 2's turn term a poor model of it.)

use std::f64::consts::{PI, TAU};

use roam_world::scenario::{MotionSpec, TimeSpec, UnicycleSpec};

use crate::event::Event;
use crate::translate::{translate, Moved};
use crate::world::World;

/// An angle in [-π, π).
pub fn wrap(angle: f64) -> f64 {
    (angle + PI).rem_euclid(TAU) - PI
}

/// The unicycle's limits for one step, from the scenario's `motion` and `time`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Unicycle {
    /// μ of paper 002 Eq. 1: the move asked for is μ·|u|, metres.
    pub step_mu: f64,
    /// Top forward speed, m/s.
    pub v_max_m_per_s: f64,
    /// Top turn rate, rad/s.
    pub w_max_rad_per_s: f64,
    /// Sim time per step, seconds.
    pub step_s: f64,
}

/// Where a unicycle ends a step and which way it faces.
#[derive(Debug, Clone, PartialEq)]
pub struct Stepped {
    pub moved: Moved,
    /// The heading after the step, radians in [-π, π).
    pub heading: f64,
}

impl Unicycle {
    pub fn new(motion: &MotionSpec, spec: &UnicycleSpec, time: &TimeSpec) -> Unicycle {
        Unicycle {
            step_mu: motion.step_mu,
            v_max_m_per_s: spec.v_max_m_per_s,
            w_max_rad_per_s: spec.w_max_rad_per_s,
            step_s: time.step_s,
        }
    }

    /// One step of the rule above for a robot at `at` facing `heading`, given command `u`
    /// and the transition noise `nu` already drawn, against the world as it is now.
    pub fn step(
        &self,
        at: [f64; 2],
        heading: f64,
        u: [f64; 2],
        nu: [f64; 2],
        world: &World,
    ) -> Stepped {
        if u == [0.0, 0.0] {
            return Stepped {
                moved: Moved {
                    at,
                    events: Vec::new(),
                },
                heading,
            };
        }
        let max_turn = self.w_max_rad_per_s * self.step_s;
        let error = wrap(u[1].atan2(u[0]) - heading);
        let turn = error.clamp(-max_turn, max_turn);
        let heading = wrap(heading + turn);
        let driving_s = (self.step_s - turn.abs() / self.w_max_rad_per_s).max(0.0);
        let requested = self.step_mu * u[0].hypot(u[1]);
        let top = self.v_max_m_per_s * self.step_s;
        let mut events = Vec::new();
        if requested > top {
            events.push(Event::SpeedClipped {
                requested_m: requested,
                allowed_m: top,
            });
        }
        let forward = requested.min(self.v_max_m_per_s * driving_s);
        let step = [forward * heading.cos(), forward * heading.sin()];
        Stepped {
            moved: translate(at, step, nu, world, events),
            heading,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn wrap_keeps_angles_in_one_turn() {
        assert_eq!(wrap(0.0), 0.0);
        assert!((wrap(3.0 * PI / 2.0) + PI / 2.0).abs() < 1e-12);
        assert!((wrap(-3.0 * PI / 2.0) - PI / 2.0).abs() < 1e-12);
        assert!((wrap(PI) + PI).abs() < 1e-12, "π is written -π");
        for k in -20..20 {
            let a = wrap(f64::from(k) * 0.7);
            assert!((-PI..PI).contains(&a), "{a}");
        }
    }
}
