//! One variant's week: the warehouse's sim with every robot, one executive in process
//! per robot ([`InProcessExecutive`], the executive's own window machine), the
//! planner's own code for their plans, and the fleet's mapper fed every robot's
//! observation every step; the shift repeated `days` times on one clock, so the
//! world (its objects) and the fleet's map carry over from shift to shift.

use std::time::Instant;

use roam_controller::params::ApfParams;
use roam_mission::calibration::TimeModel;
use roam_mission::config::ExecutiveConfig;
use roam_mission::information::InformationScale;
use roam_planner::coupling::{Coupling, DEFAULT_NEWS_FLOOR};
use roam_planner::params::GaParams;
use roam_planner::world::World;
use roam_proto::controller::Mission;
use roam_proto::planner::{Plan, PlanRequest, PlannerModel};
use roam_sim::semi_static::landed_truth;
use roam_world::seed::splitmix64;

use crate::closed_loop::episode::{EpisodeError, PositionSource};
use crate::closed_loop::stepper::Stepper;
use crate::reproduce::executive::{InProcessExecutive, Io, Step};

use super::error::FleetError;
use super::events::ChangeLog;
use super::mapper::FleetMapper;
use super::measure::{MapSample, WeekRecord, WindowRecord, PATH_EVERY_STEPS};
use super::options::FleetOptions;
use super::seen::SeenWorld;
use super::variant::{FleetVariant, Planning};
use super::world::FleetWorld;

/// Sim seconds between two samples of the map error.
pub const MAP_SAMPLE_S: f64 = 60.0;

/// The sim's stream of a week (common to every variant).
const SIM_STREAM: u64 = 0x46_4C_45_45_54_5F_53_49;

/// A robot's plan seed (common to every variant).
fn plan_seed(seed: u64, robot: usize) -> u64 {
    splitmix64(seed ^ splitmix64(0x504C_414E ^ robot as u64))
}

/// What robot `index` of the shift runs under `variant` with `tasks`: the executive's
/// configuration the batch and `roam demo --fleet` both give it (its plan seed from the
/// batch's `seed`, the variant's rules, the PEB cost `w_loc` forgiving `peb_free_m`),
/// so the two make the same decisions from the same inputs.
pub fn robot_config(
    variant: FleetVariant,
    robot: &str,
    index: usize,
    tasks: Vec<roam_mission::tasks::Task>,
    options: &FleetOptions,
) -> ExecutiveConfig {
    let base = ExecutiveConfig {
        robot: robot.to_owned(),
        tasks,
        max_generations: Some(options.generations),
        seed: plan_seed(options.seed, index),
        peb_free_m: Some(options.peb_free_m),
        // Routes being driven are replanned when the fleet's belief blocks them only in
        // the `news_map_replans` variant (variant.rs): no effect shown yet.
        obstacle_inflation_m: super::seen::OBSTACLE_INFLATION_M,
        ..ExecutiveConfig::default()
    };
    variant.config(base, options.w_loc, options.model)
}

/// The planner, the patrol and the mapper as one robot's executive asks them.
struct FleetIo<'r, 'w> {
    world: &'w FleetWorld,
    /// The grid plans are made on: the static one, or around what the fleet has seen.
    planning_world: &'r World,
    planning: Planning,
    stepper: &'r mut Stepper,
    mapper: &'r mut FleetMapper,
    robot: &'r str,
    index: usize,
    now_s: f64,
    patrol_at: &'r mut usize,
    latencies: &'r mut Vec<f64>,
    /// The time model the robot plans with (for its reservations).
    s_per_m: f64,
    radius_m: f64,
}

impl Io for FleetIo<'_, '_> {
    fn send(&mut self, mission: &Mission) -> Result<(), EpisodeError> {
        if mission.recovery {
            self.stepper
                .set_recovery(self.robot, mission.waypoints.clone())?;
            return Ok(());
        }
        self.stepper
            .set_mission(self.robot, mission.waypoints.clone())?;
        if let Planning::News {
            reservations: true, ..
        } = self.planning
        {
            // A failed reservation (a path off the map) leaves none: the news is then
            // only less shared, never wrong.
            let _ = self.mapper.reserve(
                self.world,
                self.robot,
                &mission.waypoints,
                self.now_s,
                self.s_per_m,
                self.radius_m,
            );
        }
        Ok(())
    }

    fn answer(&mut self, request: &PlanRequest, now_s: f64) -> Result<Plan, &'static str> {
        let started = Instant::now();
        let answer = self.plan(request, now_s);
        if request.model != PlannerModel::Shortest {
            self.latencies.push(started.elapsed().as_secs_f64());
        }
        answer
    }
}

/// The planner's own answer on `world`, a refusal as its kind.
fn answer_on(world: &World, request: &PlanRequest) -> Result<Plan, &'static str> {
    roam_planner::answer::answer(world, request, 1).map_err(|e| e.kind())
}

impl FleetIo<'_, '_> {
    fn plan(&mut self, request: &PlanRequest, now_s: f64) -> Result<Plan, &'static str> {
        let world = self.planning_world;
        if request.model == PlannerModel::Shortest {
            return answer_on(world, request);
        }
        match self.planning {
            Planning::Fastest | Planning::Static => answer_on(world, request),
            Planning::Patrol => self.patrol(request),
            Planning::News { reservations, .. } => {
                let news = self
                    .mapper
                    .news_scores(self.index, self.robot, now_s, reservations)
                    .map_err(|_| "news")?;
                let mut coupled = world.clone();
                coupled.information =
                    Coupling::News.apply(&world.information, &news, DEFAULT_NEWS_FLOOR);
                coupled.set_heuristic_compression(coupled.heuristic_compression);
                answer_on(&coupled, request)
            }
        }
    }

    /// The patrol's route as the plan's answer: the planner's own answer for the
    /// shortest path (its fallback and its comparison), with the patrol as its route.
    fn patrol(&mut self, request: &PlanRequest) -> Result<Plan, &'static str> {
        let world = self.planning_world;
        let shortest = PlanRequest {
            model: PlannerModel::Shortest,
            ..request.clone()
        };
        let mut plan = answer_on(world, &shortest)?;
        let params = GaParams::with_overrides(&request.params).map_err(|_| "parameter")?;
        let model = TimeModel {
            v_lin: params.v_lin,
            v_ang: params.v_ang,
        };
        let route = self.world.patrol.as_ref().ok_or("no_patrol")?.route(
            world,
            model,
            request.start,
            request.goal,
            request.t_exec_s,
            *self.patrol_at,
        );
        let Some(route) = route else {
            return Ok(plan);
        };
        *self.patrol_at = route.left_at;
        plan.model = request.model;
        plan.cells = route
            .points
            .iter()
            .filter_map(|p| roam_world::grid::world_to_cell(&world.meta, p[0], p[1]))
            .map(|(x, y)| [x as u32, y as u32])
            .collect();
        plan.points = route.points;
        plan.t_eta_s = route.t_eta_s;
        plan.reaches_goal = true;
        plan.within_budget = true;
        Ok(plan)
    }
}

/// Runs `variant`'s week.
pub fn run_week(
    world: &FleetWorld,
    variant: FleetVariant,
    options: &FleetOptions,
) -> Result<WeekRecord, FleetError> {
    let shift = &world.shift;
    let robots = shift.robots.len();
    let configs: Vec<ExecutiveConfig> = shift
        .robots
        .iter()
        .enumerate()
        .map(|(i, r)| ExecutiveConfig {
            // The batch has no wall clock: a plan costs what the options say.
            planning_cost_s: Some(options.plan_wall_s * options.rate),
            ..robot_config(
                variant,
                &r.robot,
                i,
                shift.repeated(r, options.days),
                options,
            )
        })
        .collect();
    let scale = InformationScale {
        world: &world.planning,
        params: &world.params,
    };
    let mut executives = configs
        .iter()
        .map(|c| {
            // The fleet's plans are the greedy planner's by default, which a seed
            // route does not shorten: a replan costs what a plan costs.
            let wall = (options.plan_wall_s, options.plan_wall_s);
            InProcessExecutive::new(c, scale, options.rate, wall)
        })
        .collect::<Result<Vec<_>, _>>()?;
    let planning = variant.planning();
    let (own_maps, prior) = match planning {
        Planning::News { shared, prior, .. } => (!shared, prior),
        _ => (false, roam_mapper::news::DEFAULT_NEWS_PRIOR),
    };
    let mut mapper = FleetMapper::new(world, robots, own_maps, prior)?;
    let mut stepper = Stepper::new(
        &world.setup,
        world.sim_params,
        &ApfParams::fleet(),
        PositionSource::Estimate,
        splitmix64(options.seed ^ SIM_STREAM),
    )?;
    let names: Vec<String> = shift.robots.iter().map(|r| r.robot.clone()).collect();
    let mut patrol_at = vec![0usize; robots];
    let mut record = WeekRecord::new(variant, robots);
    let mut changes = ChangeLog::default();
    let end_s = options.days as f64 * shift.length_s;
    let mut next_sample_s = MAP_SAMPLE_S;
    let mut seen = SeenWorld::default();
    let radius_m = world.sim_params.sensing.observation_radius_m;
    let started = Instant::now();
    while executives.iter().any(|e| !e.done()) && stepper.sim().time_s() < end_s {
        let out = stepper.step()?;
        let t = out.time_s;
        let landed = landed_truth(stepper.sim().world().objects());
        changes.update(&landed, t);
        if options.avoid_seen && seen.due(t) {
            seen.refresh(world, &mapper.belief(world, t)?, t)?;
        }
        let obstacles = seen.take_changed();
        for r in &out.robots {
            let Some(i) = names.iter().position(|n| *n == r.robot) else {
                continue;
            };
            if let Some(o) = &r.messages.observation {
                mapper.observe(world, i, o, t)?;
                changes.observe(o, t);
            }
            record.robot_step(i, r.decision.as_ref());
            if t <= shift.length_s && out.step % PATH_EVERY_STEPS == 0 {
                record.paths[i].push(r.messages.truth.at);
            }
            let step = Step {
                time_s: t,
                truth: r.messages.truth.at,
                estimate: r.estimate.clone(),
                decision: r.decision,
            };
            let exec = &mut executives[i];
            let s_per_m = exec.time_model().v_lin;
            let mut io = FleetIo {
                world,
                planning_world: seen.world(world),
                planning,
                stepper: &mut stepper,
                mapper: &mut mapper,
                robot: &names[i],
                index: i,
                now_s: t,
                patrol_at: &mut patrol_at[i],
                latencies: &mut record.plan_latencies_s,
                s_per_m,
                radius_m,
            };
            exec.on_step(&step, &mut io)?;
            if let Some(set) = &obstacles {
                exec.on_obstacles(set.clone(), &mut io)?;
            }
            for finished in exec.take_finished() {
                record
                    .windows
                    .push(WindowRecord::of(world, i, shift.length_s, finished));
            }
        }
        if t >= next_sample_s {
            next_sample_s += MAP_SAMPLE_S;
            let belief = mapper.belief(world, t)?;
            let truth = world.semi_static_truth(&landed);
            record
                .maps
                .push(MapSample::score(world, t, &belief, &truth)?);
        }
    }
    record.localization_errors = Some(stepper.localization_errors);
    record.first_localization_error = stepper.first_localization_error.clone();
    record.finish(
        changes,
        stepper.sim().time_s(),
        started.elapsed().as_secs_f64(),
    );
    Ok(record)
}
