//! The patrol an operator would run without roam: each idle robot drives a fixed loop
//! through every aisle of the warehouse, as far as its window allows, and is back at
//! its next task on time. What roam's curiosity is measured against.
//!
//! **The loop** ([`Patrol::through_aisles`]): up aisle 1, down aisle 2, up aisle 3, …
//! (a serpentine through the eleven aisles between the racks, end to end from the south
//! main aisle to the north one), then down the east aisle and back west along the south
//! main aisle, beside the dock: about 410 m. Its legs are the planner's fastest paths
//! between the loop's corners, laid out once.
//!
//! **Where the robots localize.** An operator keeps a patrol where the robots know where
//! they are: the loop never enters a cell whose PEB (localization's field from the
//! anchors, [`FleetWorld`](super::world::FleetWorld)'s) is above the controller's
//! `max_peb_m`, where roam's controller would hold the robot. An aisle that reaches into
//! the north-east anchor gap is patrolled as far as the anchors reach and left the way
//! it was entered; the legs go round the gap (by the cross aisle), and so do the ways
//! onto the loop and off it to the task where they can. Driven through the
//! gap, the patrol lost 4,400 steps a robot-day to PEB holds and 121 of 228 windows
//! were late (two shifts, seed 0): a patrol no operator would keep.
//!
//! **A window's patrol** ([`Patrol::route`]): the robot joins the loop at the corner
//! nearest to it among the next [`JOIN_AHEAD`] from where its last patrol stopped (so
//! over the days it covers the whole loop rather than the same stretch), follows the
//! loop corner by corner, and leaves it at the last corner from which the fastest path
//! to the task still fits the window's budget (paper 000 Eq. 2 with the robot's own
//! time model, as every plan is timed). The executive's window machine drives it like
//! any curious plan: the same margin, the same last-safe-moment rule, the same replans.

use roam_mission::calibration::{path_measure, TimeModel};
use roam_planner::params::GaParams;
use roam_planner::search::fastest_path;
use roam_planner::world::World;

use super::error::FleetError;

/// Corners ahead of the robot's last one among which it joins the loop.
pub const JOIN_AHEAD: usize = 3;

/// The y of the south and north main aisles, and the x of the aisles' centres.
const SOUTH_Y: f64 = 7.5;
const NORTH_Y: f64 = 34.0;
const EAST_X: f64 = 56.5;
const AISLES: usize = 11;

fn aisle_x(j: usize) -> f64 {
    7.6 + 4.0 * j as f64
}

/// The loop: its corners and the points between them.
#[derive(Debug, Clone)]
pub struct Patrol {
    corners: Vec<[f64; 2]>,
    /// The fastest path from each corner to the next (the last back to the first),
    /// the corner itself first.
    legs: Vec<Vec<[f64; 2]>>,
    /// Where the robots localize ([`Patrol::through_aisles`]): the ways onto the loop
    /// and off it to the task go there too when they can. `None` for a site's own loop.
    localized: Option<World>,
}

/// A window's patrol route.
#[derive(Debug, Clone, PartialEq)]
pub struct PatrolRoute {
    pub points: Vec<[f64; 2]>,
    pub t_eta_s: f64,
    /// The corner the robot left the loop at: where its next patrol goes on from.
    pub left_at: usize,
}

impl Patrol {
    /// The warehouse's loop (module doc) on `localized`: the planning world with every
    /// cell where the robots do not localize blocked ([`FleetWorld`](super::world::FleetWorld)
    /// builds it). Each aisle is driven from the south main aisle north as far as
    /// `localized` lets it; an aisle cut short is gone up and back down.
    pub fn through_aisles(localized: &World) -> Result<Patrol, FleetError> {
        let mut corners = Vec::new();
        let mut north_side = false;
        for x in (1..=AISLES).map(aisle_x).chain([EAST_X]) {
            let Some(north) = reach_north(localized, x) else {
                continue;
            };
            let (south, whole) = ([x, SOUTH_Y], north[1] >= NORTH_Y);
            if !whole {
                // Cut short: up as far as the anchors reach and back down; the loop
                // is on the south side after it, whichever side it came from.
                corners.extend([south, north, south]);
                north_side = false;
            } else if north_side {
                corners.extend([north, south]);
                north_side = false;
            } else {
                corners.extend([south, north]);
                north_side = true;
            }
        }
        // Home along the south main aisle: the loop's first corner is its last's west.
        if corners.last().is_some_and(|c| c[1] >= NORTH_Y) {
            corners.push([EAST_X, SOUTH_Y]);
        }
        corners.dedup();
        let mut patrol = Patrol::through(localized, corners)?;
        patrol.localized = Some(localized.clone());
        Ok(patrol)
    }

    /// A loop through `corners` in order and back to the first, each leg the planner's
    /// fastest path on `world` (a shift file's `patrol:`).
    pub fn through(world: &World, corners: Vec<[f64; 2]>) -> Result<Patrol, FleetError> {
        let params = GaParams::default();
        let legs = (0..corners.len())
            .map(|i| {
                let (a, b) = (corners[i], corners[(i + 1) % corners.len()]);
                path(world, &params, a, b).ok_or_else(|| {
                    FleetError::World(format!("the patrol loop cannot go from {a:?} to {b:?}"))
                })
            })
            .collect::<Result<Vec<_>, _>>()?;
        Ok(Patrol {
            corners,
            legs,
            localized: None,
        })
    }

    pub fn corners(&self) -> &[[f64; 2]] {
        &self.corners
    }

    /// The whole loop's points, once round.
    pub fn loop_points(&self) -> Vec<[f64; 2]> {
        self.legs.iter().flatten().copied().collect()
    }

    /// The patrol from `from` to `to` within `budget_s` under `model`, going on from
    /// corner `last` (module doc); `None` when not even joining the loop fits.
    pub fn route(
        &self,
        world: &World,
        model: TimeModel,
        from: [f64; 2],
        to: [f64; 2],
        budget_s: f64,
        last: usize,
    ) -> Option<PatrolRoute> {
        let n = self.corners.len();
        let params = GaParams {
            v_lin: model.v_lin,
            v_ang: model.v_ang,
            ..GaParams::default()
        };
        let eta = |points: &[[f64; 2]]| {
            let (d, theta) = path_measure(points);
            model.eta(d, theta)
        };
        let join = (0..JOIN_AHEAD).map(|k| (last + k) % n).min_by(|&a, &b| {
            roam_mission::path::distance(self.corners[a], from)
                .total_cmp(&roam_mission::path::distance(self.corners[b], from))
        })?;
        // Onto the loop and off it where the robots localize when that is possible (a
        // task's place may itself be where they do not), else on `world`.
        let way = |a: [f64; 2], b: [f64; 2]| {
            self.localized
                .as_ref()
                .and_then(|l| path(l, &params, a, b))
                .or_else(|| path(world, &params, a, b))
        };
        let mut so_far = way(from, self.corners[join])?;
        let mut best: Option<PatrolRoute> = None;
        let mut at = join;
        for _ in 0..=n {
            // Every later corner costs the loop so far, and at least the straight line
            // from here to the task (the triangle inequality): past the budget, none fits.
            let lower =
                eta(&so_far) + model.v_lin * roam_mission::path::distance(self.corners[at], to);
            if lower > budget_s {
                break;
            }
            if let Some(home) = way(self.corners[at], to) {
                let mut points = so_far.clone();
                points.extend(home.iter().skip(1));
                let t = eta(&points);
                if t <= budget_s {
                    best = Some(PatrolRoute {
                        points,
                        t_eta_s: t,
                        left_at: at,
                    });
                }
            }
            so_far.extend(self.legs[at].iter().skip(1));
            at = (at + 1) % n;
        }
        best
    }
}

/// How far short of where the anchors stop reaching a patrol turns back in an aisle cut
/// short, metres: the planning cell at the edge is one a robot can stand in, but part of
/// it is already without a fix.
const TURN_BACK_M: f64 = 1.0;

/// The northmost point of the aisle at `x`, from the south main aisle up to the north
/// one, that `localized` lets a robot drive to along the aisle's centre line, checked
/// every planning cell, [`TURN_BACK_M`] short of a blocked cell; `None` when the
/// aisle's south end is blocked.
fn reach_north(localized: &World, x: f64) -> Option<[f64; 2]> {
    let step = localized.meta.resolution;
    let steps = ((NORTH_Y - SOUTH_Y) / step).ceil() as usize;
    let mut reached = None;
    for i in 0..=steps {
        let y = (SOUTH_Y + i as f64 * step).min(NORTH_Y);
        let free = localized
            .cell_at(x, y)
            .is_some_and(|c| localized.is_traversable(c));
        if !free {
            return reached.map(|[x, y]: [f64; 2]| [x, (y - TURN_BACK_M).max(SOUTH_Y)]);
        }
        reached = Some([x, y]);
    }
    reached
}

/// The fastest path's cell centres from `a` to `b`, `a`'s cell first.
fn path(world: &World, params: &GaParams, a: [f64; 2], b: [f64; 2]) -> Option<Vec<[f64; 2]>> {
    let (start, goal) = (world.cell_at(a[0], a[1])?, world.cell_at(b[0], b[1])?);
    let cells = fastest_path(world, params, start, goal)?;
    Some(world.centers(&cells))
}
