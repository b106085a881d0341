//! The plan as the robot drives it: at a coarser planning resolution, the fittest
//! candidates refined onto the map's cells until one fits the budget when driven.

use crate::best::{PlanSource, Scored};
use crate::curiosity::{Evaluation, Evaluator, Model};
use crate::metrics::{path_metrics, PathMetrics};
use crate::params::GaParams;
use crate::resolution;
use crate::world::World;

use super::check::Checked;
use super::spec::{PlanSpec, ShortestOutcome};

/// [`ShortestOutcome`] of a checked request: its fastest path as driven, measured as
/// the `shortest` baseline measures it.
pub(super) fn fastest_as_driven(
    world: &World,
    params: &GaParams,
    checked: &Checked,
) -> ShortestOutcome {
    match (&world.fine, &checked.fastest_driven) {
        (Some(fine), Some(driven)) => {
            let path = fine.planning_cells(driven);
            ShortestOutcome {
                metrics: path_metrics(world, params, &path),
                path,
                cells: fine.grid_cells(driven),
                points: fine.centers(driven),
                t_eta_s: checked.fastest_t_eta_s,
            }
        }
        _ => ShortestOutcome {
            metrics: path_metrics(world, params, &checked.fastest),
            path: checked.fastest.clone(),
            cells: world.grid_cells(&checked.fastest),
            points: world.centers(&checked.fastest),
            t_eta_s: checked.fastest_t_eta_s,
        },
    }
}

/// The plan as the robot drives it.
pub(super) struct Driven {
    pub(super) chosen: Scored,
    pub(super) t_eta_s: f64,
    pub(super) metrics: PathMetrics,
    pub(super) cells: Vec<[u32; 2]>,
    pub(super) points: Vec<[f64; 2]>,
}

/// How many of the fittest candidates are driven on the map's cells, at most, before
/// falling back on the fastest path (each is one search of at most `L · k² · 9` states).
pub const MAX_DRIVEN_CANDIDATES: usize = 8;

/// The fittest candidate, as driven. At the map's resolution that is `ranked[0]` as it
/// is. At a coarser planning resolution each candidate, fittest first, is refined onto
/// the map's cells ([`resolution::refine`]) until one fits t_exec when driven (Eq. 2 on
/// the map's cells); the fastest path, which the budget was checked against as driven,
/// is the last resort. Its fitness is scored on the planning cells the driven path
/// passes through, with the time terms (Eqs. 4, 6, 7) of the driven t_ETA, and U_ges,
/// D and the distinct information on those planning cells (Eqs. 11, 12).
pub(super) fn drive(
    world: &World,
    spec: &PlanSpec,
    checked: &Checked,
    model: Model,
    ranked: Vec<Scored>,
) -> Driven {
    let params = &spec.params;
    let (Some(fine), Some((start, goal)), Some(fastest)) =
        (&world.fine, &checked.anchors, &checked.fastest_driven)
    else {
        let chosen = ranked.into_iter().next().unwrap_or_else(|| Scored {
            path: checked.fastest.clone(),
            evaluation: Evaluator::new(world, params, model, checked.goal, spec.t_exec_s)
                .evaluate(&checked.fastest),
            source: PlanSource::Shortest,
        });
        return Driven {
            t_eta_s: chosen.evaluation.t_eta,
            metrics: path_metrics(world, params, &chosen.path),
            cells: world.grid_cells(&chosen.path),
            points: world.centers(&chosen.path),
            chosen,
        };
    };
    let (path, source) = ranked
        .iter()
        .take(MAX_DRIVEN_CANDIDATES)
        .find_map(|candidate| {
            let driven = resolution::refine(fine, params, &candidate.path, start, goal)?;
            (fine.eta(params, &driven) <= spec.t_exec_s).then_some((driven, candidate.source))
        })
        .unwrap_or_else(|| (fastest.clone(), PlanSource::Shortest));
    let t_eta_s = fine.eta(params, &path);
    let planned = fine.planning_cells(&path);
    let mut evaluator = Evaluator::new(world, params, model, checked.goal, spec.t_exec_s);
    let evaluation = with_driven_time(evaluator.evaluate(&planned), t_eta_s, params, spec.t_exec_s);
    Driven {
        metrics: path_metrics(world, params, &planned),
        cells: fine.grid_cells(&path),
        points: fine.centers(&path),
        t_eta_s,
        chosen: Scored {
            path: planned,
            evaluation,
            source,
        },
    }
}

/// An evaluation with its time terms (Eqs. 4, 6, 7) recomputed for the driven t_ETA.
fn with_driven_time(mut e: Evaluation, t: f64, params: &GaParams, t_exec: f64) -> Evaluation {
    let f = &mut e.fitness;
    f.f2_on_time = if t < t_exec { params.w2 } else { 0.0 };
    f.f4_overtime = -params.w4 * (t - t_exec).max(0.0);
    f.f5_idle = -params.w5 * (t_exec - t).max(0.0);
    f.total = f.f1_information
        + f.f2_on_time
        + f.f3_goal
        + f.f4_overtime
        + f.f5_idle
        + f.f6_localizability;
    e.t_eta = t;
    e
}
