//! The planner as the executive asks it, in batch: the request the executive sends
//! ([`roam_mission::request::plan_request`]) answered by the planner's own
//! [`roam_planner::answer::answer`], on the map the planner service would hold.
//!
//! **What a plan costs on the mission clock** is the executive's `planning_cost_s`,
//! fixed for the batch (the services' measured cost at the demo's rate, by default), and
//! the answer reaches the window that much mission time after it was asked ([`super::day`]):
//! the robot drives on meanwhile, as it does live. Wall time never enters: the GA runs
//! its generations (the executive's `max_generations`) whatever the machine, so a day
//! repeats bit for bit.
//!
//! **The change coupling** (paper 004 into paper 000) is the planner's rule
//! ([`roam_planner::coupling::couple`]): `I'_xy = max(I_xy, C_xy)` with
//! `C_xy = round(100 · P_c(E > 0))` the mapper's `change_information` layer, here from
//! the day's [`ChangeMap`] (the mapper's code, fed the robot's observations every step)
//! at the time of the request. Live, the planner holds the mapper's last published
//! layer, at most its publication period older.

use roam_mapper::change_map::ChangeMap;
use roam_planner::coupling::couple;
use roam_planner::plan::PlanError;
use roam_planner::world::World;
use roam_proto::planner::{Plan, PlanRequest};

use super::world::DayWorld;

/// The planner one variant's day asks.
#[derive(Debug)]
pub struct Planner<'a> {
    pub world: &'a DayWorld,
    /// Plan on the static map coupled with the change layer.
    pub change: bool,
}

impl Planner<'_> {
    /// The information map a plan made now uses: the static one, or coupled with the
    /// change layer at `now_s` (module doc).
    pub fn map(&self, change: &ChangeMap, now_s: f64) -> Option<World> {
        if !self.change {
            return None;
        }
        let mut world = self.world.planning.clone();
        world.information = couple(&world.information, &change.change_scores(now_s));
        // Model II's block sums follow the information map.
        world.set_heuristic_compression(world.heuristic_compression);
        Some(world)
    }

    /// `request` answered as the planner service answers it, on the map of `now_s`.
    pub fn answer(
        &self,
        request: &PlanRequest,
        change: &ChangeMap,
        now_s: f64,
    ) -> Result<Plan, PlanError> {
        let coupled = self.map(change, now_s);
        let world = coupled.as_ref().unwrap_or(&self.world.planning);
        // One thread: the result does not depend on it, and the days run in parallel.
        roam_planner::answer::answer(world, request, 1)
    }
}
