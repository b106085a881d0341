//! The routes a plan reply gives the robot.

use roam_proto::planner::{Plan, PlannerModel};

/// A route the robot can be sent on: a plan's cell centres and their Eq. 2 ETA.
#[derive(Debug, Clone, PartialEq)]
pub struct Route {
    pub points: Vec<[f64; 2]>,
    pub t_eta_s: f64,
    /// A curious plan; `false`: the shortest path.
    pub curious: bool,
}

/// A window's plan made while the robot did the previous task.
#[derive(Debug, Clone, PartialEq)]
pub struct PlannedAhead {
    pub window: usize,
    /// Where the plan starts: the previous task's place.
    pub from: [f64; 2],
    pub route: Route,
    pub shortest: Vec<[f64; 2]>,
    pub budget_s: f64,
    /// The time to the task the budget was made from, seconds.
    pub time_left_s: f64,
    /// When the plan assumed the robot sets off (the previous task's end), mission
    /// seconds: a window that begins later takes a fresh plan instead.
    pub leave_at_s: f64,
}

/// The route a plan reply gives the robot, and the shortest path it carries: the curious
/// plan when it reaches the goal within its budget, the shortest path otherwise (which
/// is also what a `model: shortest` reply is, the fallback for a budget it does not
/// fit). `None` for a curious reply without the shortest path (a planner that did not
/// attach it): the executive cannot compare, or fall back.
pub fn routes(plan: Plan) -> Option<(Route, Vec<[f64; 2]>)> {
    if plan.model == PlannerModel::Shortest {
        let shortest = plan
            .shortest
            .map_or_else(|| plan.points.clone(), |s| s.points);
        let route = Route {
            points: plan.points,
            t_eta_s: plan.t_eta_s,
            curious: false,
        };
        return Some((route, shortest));
    }
    let shortest = plan.shortest?;
    let route = if plan.reaches_goal && plan.within_budget {
        Route {
            points: plan.points,
            t_eta_s: plan.t_eta_s,
            curious: true,
        }
    } else {
        Route {
            points: shortest.points.clone(),
            t_eta_s: shortest.t_eta_s,
            curious: false,
        }
    };
    Some((route, shortest.points))
}
