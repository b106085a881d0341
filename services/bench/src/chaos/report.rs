//! What the chaos day prints: each fault with how the roles came back, each window with
//! the faults that fell in it, what the map kept, and the goals judged from the figures.

use std::collections::BTreeMap;

use serde::Serialize;

use super::marks::MarksOutcome;
use super::schedule::Fault;

/// A role may take at most this long from its restart (or its link's heal) to hold its
/// liveliness token again.
pub const LIVE_AGAIN_GOAL_S: f64 = 5.0;
/// A window late by up to this much more than its faults lasted is still explained: a
/// sim step and the executive's own replan.
pub const LATE_SLACK_S: f64 = 2.0;

/// How one role came back after a fault.
#[derive(Debug, Clone, Serialize)]
pub struct RoleRecovery {
    pub role: String,
    /// From its restart (or the heal, or SIGCONT) to its liveliness token, seconds;
    /// `None`: never within the bench's patience.
    pub live_again_s: Option<f64>,
    /// From the same moment to its first good answer (a reply, or a publication on its
    /// key), seconds.
    pub first_answer_s: Option<f64>,
}

/// One fault as it happened.
#[derive(Debug, Clone, Serialize)]
pub struct FaultOutcome {
    pub fault: Fault,
    pub what: String,
    /// Wall seconds the role was down, cut or frozen.
    pub hold_s: f64,
    /// From the fault to the first of its roles' liveliness tokens gone, as the bench
    /// saw it, seconds; `None`: never gone (a cut or freeze shorter than Zenoh's 10 s
    /// lease leaves the sessions up; the router's own kill takes every token's witness
    /// with it).
    pub token_gone_s: Option<f64>,
    /// The sim clock when it struck and when every role it touched answered again.
    pub sim_from_s: f64,
    pub sim_to_s: f64,
    pub roles: Vec<RoleRecovery>,
    /// The map's layer versions went back across it (names).
    pub layers_gone_back: Vec<String>,
}

impl FaultOutcome {
    /// Sim seconds from the fault to the last of its roles answering.
    pub fn sim_span_s(&self) -> f64 {
        (self.sim_to_s - self.sim_from_s).max(0.0)
    }
}

/// One task's window and the faults in it.
#[derive(Debug, Clone, Serialize)]
pub struct WindowOutcome {
    pub robot: String,
    pub task: String,
    pub task_start_s: f64,
    /// Whether the executive reported the window at all.
    pub reported: bool,
    pub arrival_s: Option<f64>,
    /// Seconds after the task's start it arrived (0 when on time); `None` when it never
    /// arrived or was not reported.
    pub late_by_s: Option<f64>,
    /// The report's reasons for changing the route (`silent`, `no_planner`,
    /// `resumed`, …).
    pub reasons: Vec<String>,
    /// The faults that struck between the previous task and this one.
    pub faults: Vec<String>,
    /// Their sim spans summed, seconds.
    pub faults_sim_s: f64,
    /// On time, or late by no more than its faults lasted (and [`LATE_SLACK_S`]).
    pub explained: bool,
}

/// One goal of the chaos day, judged from the figures.
#[derive(Debug, Clone, Serialize)]
pub struct Goal {
    pub goal: String,
    pub value: f64,
    pub target: f64,
    pub holds: bool,
}

/// `roam bench chaos`'s report.
#[derive(Debug, Clone, Serialize)]
pub struct ChaosReport {
    /// The built-in day or the warehouse shift (its robots and length).
    pub site: String,
    pub seed: u64,
    pub rate: f64,
    pub partition_s: f64,
    pub freeze_s: f64,
    pub faults: Vec<FaultOutcome>,
    pub windows: Vec<WindowOutcome>,
    pub marks: MarksOutcome,
    pub derived_layers_checked: usize,
    pub derived_layers_out_of_step: Vec<String>,
    /// The controller's last state for each robot of the day.
    pub controller_states_at_end: BTreeMap<String, String>,
    pub robots_held_at_end: usize,
    /// Processes that exited on their own and were started again, by name.
    pub unplanned_restarts: BTreeMap<String, u32>,
    pub wall_s: f64,
    pub goals: Vec<Goal>,
}

/// The windows of `robot`'s tasks: each with its report (the last one for the task) and
/// the faults between the previous task's end and its start.
pub(super) fn windows(
    robot: &str,
    tasks: &[(String, f64, f64)],
    reports: &[roam_proto::mission::WindowReport],
    faults: &[FaultOutcome],
) -> Vec<WindowOutcome> {
    let mut from = 0.0;
    tasks
        .iter()
        .map(|(task, start_s, duration_s)| {
            let report = reports
                .iter()
                .rev()
                .find(|r| r.robot == robot && &r.task == task);
            let arrival_s = report.and_then(|r| r.arrival_s);
            let late_by_s = arrival_s.map(|a| (a - start_s).max(0.0));
            let inside: Vec<&FaultOutcome> = faults
                .iter()
                .filter(|f| f.sim_to_s >= from && f.sim_from_s <= *start_s)
                .collect();
            let faults_sim_s: f64 = inside.iter().map(|f| f.sim_span_s()).sum();
            let explained = late_by_s.is_some_and(|late| late <= faults_sim_s + LATE_SLACK_S);
            let window = WindowOutcome {
                robot: robot.to_owned(),
                task: task.clone(),
                task_start_s: *start_s,
                reported: report.is_some(),
                arrival_s,
                late_by_s,
                reasons: report.map(|r| r.replan_reasons.clone()).unwrap_or_default(),
                faults: inside.iter().map(|f| f.what.clone()).collect(),
                faults_sim_s,
                explained,
            };
            from = start_s + duration_s;
            window
        })
        .collect()
}

/// What the chaos day must keep, judged from its figures: every role back soon, every
/// window explained, nothing acked lost, derived layers in step, no robot held.
pub(super) fn goals(report: &ChaosReport) -> Vec<Goal> {
    let goal = |goal: &str, value: f64, target: f64, holds: bool| Goal {
        goal: goal.to_owned(),
        value,
        target,
        holds,
    };
    let kills: Vec<&RoleRecovery> = report
        .faults
        .iter()
        .filter(|f| matches!(f.fault, Fault::Kill { .. }))
        .flat_map(|f| &f.roles)
        .collect();
    let slowest = kills
        .iter()
        .map(|r| r.live_again_s.unwrap_or(f64::INFINITY))
        .fold(0.0, f64::max);
    let unexplained = report.windows.iter().filter(|w| !w.explained).count();
    let gone_back: usize = report.faults.iter().map(|f| f.layers_gone_back.len()).sum();
    vec![
        goal(
            "every killed role holds its token again within 5 s of its restart (slowest, s)",
            slowest,
            LIVE_AGAIN_GOAL_S,
            slowest <= LIVE_AGAIN_GOAL_S,
        ),
        goal(
            "every window on time or late by no more than its faults lasted (windows not)",
            unexplained as f64,
            0.0,
            unexplained == 0,
        ),
        goal(
            "acked map updates lost",
            report.marks.acked_lost as f64,
            0.0,
            report.marks.acked == 0 || report.marks.acked_lost == 0,
        ),
        goal(
            "derived layers out of step at the end",
            report.derived_layers_out_of_step.len() as f64,
            0.0,
            report.derived_layers_out_of_step.is_empty(),
        ),
        goal(
            "layer versions gone back across a fault",
            gone_back as f64,
            0.0,
            gone_back == 0,
        ),
        goal(
            "robots held at the end of the day",
            report.robots_held_at_end as f64,
            0.0,
            report.robots_held_at_end == 0,
        ),
    ]
}

#[cfg(test)]
mod tests {
    use super::*;
    use roam_proto::mission::WindowReport;

    fn fault(what: &str, from: f64, to: f64) -> FaultOutcome {
        FaultOutcome {
            fault: Fault::Kill { role: what.into() },
            what: what.into(),
            hold_s: 1.0,
            token_gone_s: None,
            sim_from_s: from,
            sim_to_s: to,
            roles: Vec::new(),
            layers_gone_back: Vec::new(),
        }
    }

    fn report(task: &str, start: f64, arrival: Option<f64>) -> WindowReport {
        let json = serde_json::json!({
            "robot": "robot", "task": task, "window": 0, "began_s": 0.0,
            "task_start_s": start, "arrival_s": arrival, "on_time": false,
            "budget_s": 0.0, "planned_information": 0.0, "driven_information": 0.0,
            "shortest_information": 0.0, "replans": 0, "replan_reasons": [],
        });
        serde_json::from_value(json).expect("a window report")
    }

    #[test]
    fn a_window_late_by_its_faults_is_explained_and_one_late_beyond_them_is_not() {
        let tasks = vec![
            ("a".to_owned(), 75.0, 5.0),
            ("b".to_owned(), 165.0, 5.0),
            ("c".to_owned(), 245.0, 5.0),
        ];
        let faults = vec![
            fault("kill controller", 100.0, 112.0),
            fault("kill sim", 200.0, 201.0),
        ];
        let reports = vec![
            report("a", 75.0, Some(70.0)),
            report("b", 165.0, Some(175.0)),
            report("c", 245.0, Some(250.0)),
        ];
        let w = windows("robot", &tasks, &reports, &faults);
        assert!(w[0].explained && w[0].faults.is_empty() && w[0].late_by_s == Some(0.0));
        assert_eq!(w[1].faults, vec!["kill controller"]);
        assert!(w[1].explained, "late 10 s after a 12 s fault: {:?}", w[1]);
        assert!(!w[2].explained, "late 5 s after a 1 s fault: {:?}", w[2]);
        let unreported = windows("robot", &tasks, &reports[..1], &faults);
        assert!(!unreported[1].reported && !unreported[1].explained);
    }
}
