//! One downtime window, as the executive's window machine runs it (`roam_mission::window`), on
//! the mission clock of the sim: the plans (made ahead during the last task, or now), the
//! mission, the [`Watch`]'s decisions on every step's estimate and controller status,
//! the replans they ask for, the arrival, the time model learning from the arrived
//! mission, the next window planned during the task, and the wait at the task.
//!
//! Every step is an estimate and a controller status, in that order, then a tick (the
//! executive's 20 ms tick is finer than the sim's 0.4 s step). Wall time is mission
//! time: statuses come every step, so the lost-mission rule never fires here.
//!
//! The planner is asked in process here, for the shortest path and then (when
//! curiosity fits the budget) the curious one, as the executive did before its plan
//! reply carried the shortest path: the same paths and the same GA seeds, and no
//! request to save.

use super::day::{DayRun, PlannedAhead};
use super::measure::{planned_path, Leg, TimeModelUse, Track, WindowResult};
use super::DaysError;
use roam_mission::calibration::path_measure;
use roam_mission::path::distance;
use roam_mission::tasks::Task;
use roam_mission::watch::{Decision, Reason, Status, Watch};
use roam_mission::window::PREPLAN_FROM_M;

/// A replan's reason as the report names it.
pub fn reason_name(reason: Reason) -> &'static str {
    match reason {
        Reason::ControllerSilent => "silent",
        Reason::Stuck => "stuck",
        Reason::EtaSlipped => "late",
        Reason::PushedOffPath => "off_path",
        Reason::Slack => "slack",
        Reason::Behind => "behind",
    }
}

impl DayRun<'_> {
    /// Window `w` toward `task`; `None` when the task was over before the window began.
    pub fn window(
        &mut self,
        w: usize,
        task: &Task,
        next: Option<&Task>,
    ) -> Result<Option<WindowResult>, DaysError> {
        let began = self.robot.now_s();
        if began >= task.start_s + task.duration_s {
            return Ok(None);
        }
        let from = self.here();
        let mut track = Track::default();
        if let Some(&at) = self.truth.last() {
            track.truth.push(at);
        }
        let mut rank = 0;
        let planned_ahead = self
            .planned_ahead
            .take()
            .filter(|p| p.window == w && distance(p.from, from) <= PREPLAN_FROM_M);
        let planned = match planned_ahead {
            Some(p) => {
                rank = p.ranks;
                Some((p.shortest, p.plan, p.budget_s))
            }
            None => self.first_plans(None, task, w, &mut rank, None, Some(&mut track))?,
        };
        let Some((shortest, plan, budget_s)) = planned else {
            return Ok(Some(self.given_up(w, task, began, rank, &track)));
        };
        let model = self.time_model();
        let mut legs = vec![Leg::new(plan.points.clone())];
        let mut waypoints = self.waypoints(&plan);
        self.robot.send(waypoints.clone())?;
        let first_sent_at = self.robot.now_s();
        let mut sent_at = first_sent_at;
        let mut current_path: Vec<[f64; 2]> = std::iter::once(from)
            .chain(plan.points.iter().copied())
            .collect();
        let mut watch = Watch::new(
            self.watch_params(),
            task.start_s,
            plan.points.clone(),
            first_sent_at,
            first_sent_at,
        );
        let mut reasons = Vec::new();
        let mut held_s = 0.0;
        let arrival = loop {
            let step = self.advance(Some(&mut track))?;
            let now = step.time_s;
            let status = step.status();
            if let (Some(Status::Active { distance_left_m }), Some(leg)) = (status, legs.last_mut())
            {
                leg.progress(distance_left_m);
            }
            let mut decision = Decision::Keep;
            if let Some(p) = step.estimate {
                decision = watch.on_estimate(p);
            }
            if let (Decision::Keep, Some(s)) = (decision, status) {
                decision = watch.on_status(s, now, now, self.plan_cost_s);
            }
            if decision == Decision::Keep {
                decision = watch.on_tick(now, now);
            }
            let (reason, curious, resend) = match decision {
                Decision::Keep => continue,
                Decision::Arrived { at_s } => break Some(at_s),
                Decision::GiveUp => break None,
                Decision::Replan {
                    reason,
                    curious,
                    resend,
                } => (reason, curious, resend),
            };
            // Slack pays for the robot waiting while it plans, so the new path starts
            // where the robot is rather than where it was.
            let hold_from = (reason == Reason::Slack).then_some(now);
            if hold_from.is_some() {
                self.robot.send(Vec::new())?;
            }
            let here = self.here();
            let Ok(shortest_here) = self
                .planner
                .shortest(None, here, task.at, self.time_model())
            else {
                if hold_from.is_some() {
                    // Held for nothing: back on the path it had.
                    self.robot.send(waypoints.clone())?;
                }
                continue;
            };
            let (plan, _) = self.plan_window(
                here,
                task,
                w,
                &mut rank,
                &shortest_here,
                curious,
                None,
                Some(&mut track),
            )?;
            let now = self.robot.now_s();
            if let Some(t0) = hold_from {
                held_s += now - t0;
            }
            reasons.push(reason_name(reason));
            let path: Vec<[f64; 2]> = std::iter::once(here)
                .chain(plan.points.iter().copied())
                .collect();
            watch.replanned(path.clone(), resend, now, now);
            legs.push(Leg::new(plan.points.clone()));
            waypoints = self.waypoints(&plan);
            self.robot.send(waypoints.clone())?;
            sent_at = now;
            current_path = path;
        };
        // The time model learns from the mission that arrived, driven as planned from
        // where it was sent, in the planner's own terms (Eq. 2's sums on the cells).
        let time_model = arrival.map(|at| {
            let (d, theta) = path_measure(&current_path);
            let took_s = at - sent_at;
            if self.settings.calibrate {
                self.calibration.add_planned(d, theta, took_s);
            }
            let predicted_s = model.eta(d, theta);
            self.margin.learn(predicted_s, took_s);
            TimeModelUse {
                v_lin: model.v_lin,
                v_ang: model.v_ang,
                predicted_s,
                took_s,
                error: if took_s > 0.0 {
                    (predicted_s - took_s) / took_s
                } else {
                    0.0
                },
            }
        });
        let window_s = task.start_s - began;
        let driving_s = arrival.map_or(0.0, |at| at - first_sent_at);
        let planned = planned_path(&legs, arrival.is_some());
        let planned_information =
            roam_mission::information::gathered(&self.world.planning, &self.world.params, &planned);
        let driven_information = track.information(self.world);
        let result = WindowResult {
            window: w,
            task: task.name.clone(),
            began_s: began,
            task_start_s: task.start_s,
            window_s,
            arrival_s: arrival,
            late: arrival.is_none_or(|a| a > task.start_s),
            driving_s,
            share: if window_s > 0.0 {
                driving_s / window_s
            } else {
                0.0
            },
            waited_for_plan_s: first_sent_at - began,
            held_s,
            early_s: arrival
                .map(|a| task.start_s - a)
                .filter(|early| *early >= 0.0),
            budget_s,
            curious: plan.curious,
            first_plan_cells: plan.points.len(),
            ga_plans: rank,
            driven_information,
            planned_information,
            shortest_information: shortest.information,
            driven_over_planned: (planned_information > 0.0)
                .then(|| driven_information / planned_information),
            changing_cells_seen: track.changing_cells_seen(self.world),
            peb_mean_m: track.peb_mean_m(),
            halted_steps: track.halted_steps,
            estimate_rms_m: track.estimate_rms_m(),
            replans: reasons,
            time_model,
        };
        // The next window is planned while the robot does this task, from its place,
        // so that planning costs the next window nothing.
        let leave_at = task.start_s + task.duration_s;
        if let (true, Some(_), Some(next)) = (self.settings.preplan, arrival, next) {
            let mut ranks = 0;
            let plans =
                self.first_plans(Some(task.at), next, w + 1, &mut ranks, Some(leave_at), None)?;
            if let Some((shortest, plan, budget_s)) = plans {
                if self.robot.now_s() <= leave_at {
                    self.planned_ahead = Some(PlannedAhead {
                        window: w + 1,
                        from: task.at,
                        shortest,
                        plan,
                        budget_s,
                        ranks,
                    });
                }
            }
        }
        // The task keeps the robot at its place until it ends.
        if arrival.is_some() {
            self.run_until(leave_at, None)?;
        }
        Ok(Some(result))
    }

    /// A window given up before any plan came (the planner refused every start).
    fn given_up(
        &self,
        w: usize,
        task: &Task,
        began: f64,
        ga_plans: u32,
        track: &Track,
    ) -> WindowResult {
        WindowResult {
            window: w,
            task: task.name.clone(),
            began_s: began,
            task_start_s: task.start_s,
            window_s: task.start_s - began,
            arrival_s: None,
            late: true,
            driving_s: 0.0,
            share: 0.0,
            waited_for_plan_s: self.robot.now_s() - began,
            held_s: 0.0,
            early_s: None,
            budget_s: 0.0,
            curious: false,
            first_plan_cells: 0,
            ga_plans,
            driven_information: track.information(self.world),
            planned_information: 0.0,
            shortest_information: 0.0,
            driven_over_planned: None,
            changing_cells_seen: track.changing_cells_seen(self.world),
            peb_mean_m: track.peb_mean_m(),
            halted_steps: track.halted_steps,
            estimate_rms_m: track.estimate_rms_m(),
            replans: Vec::new(),
            time_model: None,
        }
    }
}
