//! Why the indoor goal tolerance is 0.2 m and not paper 002's 0.10 m: a robot that
//! drives on noisy estimates (σ 0.085 m per axis, about the built-in day's TOA fix)
//! arrives within a step or two of reaching its goal at 0.2 m (the 90th percentile: 2
//! updates more than the drive), and dithers across it at 0.10 m until one noisy
//! estimate happens to fall inside (8 updates more, 3.2 s at the sim's 0.4 s step).
//! Seeded: the same figures on every run.

use std::f64::consts::TAU;

use roam_world::seed::splitmix64;

use crate::controller::tests::fields;
use crate::params::INDOOR_G_THRES_M;
use crate::{ApfParams, Controller, MissionState, Scheme};

/// The built-in world's step: μ·|u| = 0.2 m at most (the sim's top speed per step).
const STEP_M: f64 = 0.2;
/// The estimate's noise per axis, metres.
const SIGMA_M: f64 = 0.085;
/// Updates a trial runs at most.
const MAX_UPDATES: usize = 200;

fn controller(params: ApfParams) -> Controller {
    let (obstacles, information) = fields();
    Controller::new(params, obstacles, information)
}

/// A uniform draw in (0, 1] from a splitmix64 stream.
fn uniform(state: &mut u64) -> f64 {
    *state = splitmix64(*state);
    ((*state >> 11) as f64 + 1.0) / (1u64 << 53) as f64
}

/// Updates from 2 m short of the goal until the mission completes (at most
/// [`MAX_UPDATES`]): the robot moves along the controller's command by at most a step,
/// and the controller sees its true position plus Gaussian noise (Box–Muller).
fn updates_to_arrive(params: &ApfParams, seed: u64) -> usize {
    let mut c = controller(params.clone());
    c.set_mission(vec![[22.0, 20.0]]);
    let mut truth = [20.0, 20.0];
    let mut state = seed;
    for update in 1..=MAX_UPDATES {
        let r = (-2.0 * uniform(&mut state).ln()).sqrt() * SIGMA_M;
        let a = TAU * uniform(&mut state);
        let estimate = [truth[0] + r * a.cos(), truth[1] + r * a.sin()];
        let d = c.update(estimate, Some(0.1));
        if d.status == MissionState::Completed {
            return update;
        }
        let norm = d.u[0].hypot(d.u[1]);
        if norm > 0.0 {
            let length = (STEP_M * norm).min(STEP_M);
            truth = [
                truth[0] + length * d.u[0] / norm,
                truth[1] + length * d.u[1] / norm,
            ];
        }
    }
    MAX_UPDATES
}

/// The 90th percentile, over 200 seeded trials, of the updates a robot needs beyond
/// the ten a 2 m drive takes: the tail is what makes a robot late.
fn p90_extra_updates(params: &ApfParams) -> usize {
    let mut extra: Vec<usize> = (0..200)
        .map(|seed| updates_to_arrive(params, seed).saturating_sub(10))
        .collect();
    extra.sort_unstable();
    extra[extra.len() * 9 / 10]
}

#[test]
fn indoors_a_robot_on_noisy_estimates_arrives_without_dithering_at_its_goal() {
    let indoor = ApfParams {
        scheme: Scheme::Plain,
        ..ApfParams::indoor()
    };
    let paper = ApfParams {
        g_thres_m: 0.10,
        ..indoor.clone()
    };
    assert_eq!(indoor.g_thres_m, INDOOR_G_THRES_M);
    let at_indoor = p90_extra_updates(&indoor);
    let at_paper = p90_extra_updates(&paper);
    println!("90th percentile of the updates beyond the drive: indoor {at_indoor}, paper's g_thres {at_paper}");
    assert!(
        at_indoor <= 2,
        "indoors: {at_indoor} updates beyond the drive"
    );
    assert!(
        at_paper >= at_indoor + 4,
        "at 0.10 m: {at_paper} updates beyond the drive, indoors {at_indoor}"
    );
}
