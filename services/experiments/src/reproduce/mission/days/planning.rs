//! The planner as the executive asks it, in batch: the services' own [`plan`] with the
//! request the executive would send, on the map the planner service would hold.
//!
//! **What a plan costs on the mission clock.** A curious plan costs a fixed
//! `plan_cost_s` of mission time (the services' default deadline, 1 s, at 1× real
//! time); the shortest path (A* on 10 000 cells, milliseconds) costs nothing. Wall time
//! never enters: the GA runs its `generations` (the services' `max_generations`, 1000)
//! whatever the machine, so a day repeats bit for bit.
//!
//! **The change coupling** (paper 004 into paper 000). The planner's information map
//! is the static map combined with the mapper's change probability cell by cell,
//! `I_xy = max(I_static, round(100 · P_c(E > 0)))`, P from the day's [`ChangeMap`] (the
//! mapper's code, fed the robot's 3 m observations every step) at the time of the plan.
//! The maximum, not the change layer alone (what a planner on `information_layer:
//! change_information` plans on): a map that knows little yet (the first windows of a
//! day, the change layer zero almost everywhere) would leave the planner nothing to be
//! curious about, while the maximum keeps the static map's interest and raises the cells
//! where the world was seen to change to the score its probability earns.
//!
//! **Seeds.** A plan's seed depends only on the day, the window and the plan's rank in
//! the window (common random numbers: every variant's first plan of a window draws the
//! same GA stream).

use std::sync::atomic::AtomicBool;

use roam_mapper::change_map::ChangeMap;
use roam_planner::params::GaParams;
use roam_planner::plan::{plan, PlanError, PlanSpec};
use roam_planner::world::World;
use roam_proto::planner::PlannerModel;
use roam_world::seed::splitmix64;

use super::world::DayWorld;
use roam_mission::calibration::TimeModel;
use roam_mission::information::gathered;

/// A plan as the executive uses it.
#[derive(Debug, Clone, PartialEq)]
pub struct Planned {
    /// Cell centres from the start's cell to the goal's, world metres.
    pub points: Vec<[f64; 2]>,
    /// Paper 000 Eq. 2's ETA under the time model it was planned with, seconds.
    pub t_eta_s: f64,
    /// A curious (GA) plan; `false`: the shortest path.
    pub curious: bool,
    /// The information of its distinct cells on the static map (paper 000's measure).
    pub information: f64,
}

/// Plans for one variant's day.
#[derive(Debug)]
pub struct Planner<'a> {
    pub world: &'a DayWorld,
    pub generations: u32,
    /// W_loc of the PEB cost; 0 is off.
    pub w_loc: f64,
    /// Plan on the static map combined with the change probability.
    pub change: bool,
}

/// A seed from the day's seed, the window and the plan's rank in it (splitmix64's
/// finaliser over their mix, so that nearby inputs give unrelated seeds).
pub fn plan_seed(day_seed: u64, window: usize, rank: u32) -> u64 {
    splitmix64(day_seed ^ splitmix64((window as u64) << 32 | u64::from(rank)))
}

impl Planner<'_> {
    /// The information map a plan made now uses: the static one, or combined with the
    /// change probability at `now_s` (module doc).
    pub fn map(&self, change: &ChangeMap, now_s: f64) -> Option<World> {
        if !self.change {
            return None;
        }
        let mut world = self.world.planning.clone();
        let probability = change.probability_layer(now_s);
        for (score, p) in world.information.iter_mut().zip(&probability.cells) {
            let earned = (p.clamp(0.0, 1.0) * 100.0).round() as u8;
            *score = (*score).max(earned);
        }
        // Model II's block sums follow the information map.
        world.set_heuristic_compression(world.heuristic_compression);
        Some(world)
    }

    fn spec(
        &self,
        from: [f64; 2],
        to: [f64; 2],
        t_exec_s: f64,
        model: PlannerModel,
        time: TimeModel,
        seed: u64,
    ) -> PlanSpec {
        let mut spec = PlanSpec::batch(from, to, t_exec_s, model, self.generations, seed);
        spec.params = GaParams {
            max_generations: self.generations,
            w_loc: self.w_loc,
            v_lin: time.v_lin,
            v_ang: time.v_ang,
            ..GaParams::default()
        };
        // One thread: the result does not depend on it, and the days run in parallel.
        spec.threads = 1;
        spec
    }

    fn planned(
        &self,
        world: &World,
        outcome: &roam_planner::plan::PlanOutcome,
        curious: bool,
    ) -> Planned {
        let points = world.centers(&outcome.path);
        Planned {
            information: gathered(&self.world.planning, &self.world.params, &points),
            points,
            t_eta_s: outcome.t_eta_s,
            curious,
        }
    }

    /// The shortest path, as the executive asks for it (a day's budget).
    pub fn shortest(
        &self,
        map: Option<&World>,
        from: [f64; 2],
        to: [f64; 2],
        time: TimeModel,
    ) -> Result<Planned, PlanError> {
        let world = map.unwrap_or(&self.world.planning);
        let spec = self.spec(from, to, 86_400.0, PlannerModel::Shortest, time, 0);
        let outcome = plan(world, &spec, &AtomicBool::new(false), |_, _| {})?;
        Ok(self.planned(world, &outcome, false))
    }

    /// A curious plan (Model I, the executive's default) within `t_exec_s`; `None` when
    /// it does not reach the goal within the budget (the executive then takes the
    /// shortest path).
    pub fn curious(
        &self,
        map: Option<&World>,
        from: [f64; 2],
        to: [f64; 2],
        t_exec_s: f64,
        time: TimeModel,
        seed: u64,
    ) -> Result<Option<Planned>, PlanError> {
        let world = map.unwrap_or(&self.world.planning);
        let spec = self.spec(from, to, t_exec_s, PlannerModel::Model1, time, seed);
        let outcome = plan(world, &spec, &AtomicBool::new(false), |_, _| {})?;
        Ok((outcome.reaches_goal && outcome.within_budget)
            .then(|| self.planned(world, &outcome, true)))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn seeds_differ_by_day_window_and_rank_and_repeat() {
        let s = plan_seed(7, 1, 0);
        assert_eq!(s, plan_seed(7, 1, 0));
        let others = [plan_seed(8, 1, 0), plan_seed(7, 2, 0), plan_seed(7, 1, 1)];
        assert!(others.iter().all(|&o| o != s), "{s} {others:?}");
    }
}
