//! A robot's task sequence: places it must be at, and when.

use serde::{Deserialize, Serialize};

/// One fixed task: be at `at` by `start_s` (sim seconds) and stay `duration_s`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Task {
    pub name: String,
    /// World metres.
    pub at: [f64; 2],
    /// When the task starts, seconds on the mission clock (the sim clock when a sim runs).
    pub start_s: f64,
    /// How long the task keeps the robot at its place; the next window begins after it.
    #[serde(default = "default_duration")]
    pub duration_s: f64,
}

fn default_duration() -> f64 {
    5.0
}

/// The most tasks one executive takes.
pub const MAX_TASKS: usize = 1000;

/// Why a task list is refused.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum TaskError {
    #[error("no tasks: give at least one (name, at, start_s)")]
    Empty,
    #[error("{count} tasks; at most {max} (max_tasks)")]
    TooMany { count: usize, max: usize },
    #[error("task {name:?}: {what}")]
    Bad { name: String, what: String },
    /// Checked against a map ([`crate::day_check`]): the task's place is off the map,
    /// in a wall, its inflation or unknown space, or in a pocket no planning cell
    /// reaches; `why` says which.
    #[error("task {name:?}: its place {at:?} {why}")]
    Blocked {
        name: String,
        at: [f64; 2],
        why: String,
    },
    /// Checked against a map: the robot's start position is where no plan can begin.
    #[error("the start {at:?} {why}")]
    StartBlocked { at: [f64; 2], why: String },
    /// Checked against a map: no path at all joins the task's place to the previous
    /// one (or to the start).
    #[error("task {name:?}: its place {at:?} cannot be reached from {from}: no path joins them on this map (walls or their inflation enclose one of them)")]
    NoPath {
        name: String,
        at: [f64; 2],
        from: LegFrom,
    },
    /// Checked against a map: the fastest path (paper 000 Eq. 2, turns counted, with
    /// the robot's time model) from the end of the previous task (or from the start,
    /// at 0 s) takes longer than the gap to this task's start.
    #[error("task {name:?}: its place {at:?} cannot be reached from {from} in time: the fastest path takes {fastest_s:.1} s, the gap is {gap_s:.1} s ({missing_s:.1} s missing)")]
    Unreachable {
        name: String,
        at: [f64; 2],
        from: LegFrom,
        fastest_s: f64,
        gap_s: f64,
        missing_s: f64,
    },
    /// Checked against a map: the time model is one the planner refuses.
    #[error("the time model (v_lin {v_lin} s/m, v_ang {v_ang} s/rad) cannot time the day's drives: {what}")]
    TimeModel {
        v_lin: f64,
        v_ang: f64,
        what: String,
    },
}

/// Where a leg of the day begins: the previous task, or the robot's start position.
#[derive(Debug, Clone, PartialEq)]
pub enum LegFrom {
    Start { at: [f64; 2] },
    Task { name: String },
}

impl std::fmt::Display for LegFrom {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            LegFrom::Start { at } => write!(f, "the start {at:?}"),
            LegFrom::Task { name } => write!(f, "{name:?}"),
        }
    }
}

/// Checks a task list: finite places, start times that increase with room for each
/// task's duration.
pub fn check(tasks: &[Task]) -> Result<(), TaskError> {
    if tasks.is_empty() {
        return Err(TaskError::Empty);
    }
    if tasks.len() > MAX_TASKS {
        return Err(TaskError::TooMany {
            count: tasks.len(),
            max: MAX_TASKS,
        });
    }
    let mut free_from = f64::NEG_INFINITY;
    for t in tasks {
        let bad = |what: String| TaskError::Bad {
            name: t.name.clone(),
            what,
        };
        if !(t.at[0].is_finite() && t.at[1].is_finite()) {
            return Err(bad(format!("its place {:?} is not a finite point", t.at)));
        }
        if !(t.duration_s.is_finite() && t.duration_s >= 0.0) {
            return Err(bad(format!(
                "duration_s {} must be 0 or more seconds",
                t.duration_s
            )));
        }
        if !(t.start_s.is_finite() && t.start_s >= free_from) {
            return Err(bad(format!(
                "start_s {} must come after the previous task ends ({free_from} s)",
                t.start_s
            )));
        }
        free_from = t.start_s + t.duration_s;
    }
    Ok(())
}

/// The built-in world's downtime day (`config/scenarios/downtime.yaml`): from `start`,
/// a task at `goal1` at 75 s and one at `goal2` at 165 s, 5 s each. The shortest drives
/// take about 30 s and 35 s (paper 000's ETA), so each window holds about twice its
/// shortest drive plus the planning time: downtime to spend on curiosity.
pub fn builtin() -> Vec<Task> {
    vec![
        Task {
            name: "goal1".into(),
            at: [-2.0, 4.0],
            start_s: 75.0,
            duration_s: 5.0,
        },
        Task {
            name: "goal2".into(),
            at: [6.0, -7.0],
            start_s: 165.0,
            duration_s: 5.0,
        },
    ]
}

/// The demo's day world (`config/scenarios/day.yaml`), embedded so `roam demo` needs no
/// file.
pub const DAY_SCENARIO: &str = include_str!("../../../config/scenarios/day.yaml");

/// The day in [`DAY_SCENARIO`]: four windows. From `start` to `goal1` by 75 s, to
/// `goal2` by 165 s, a round trip back to `goal2` by 245 s (the next task is where the
/// robot is: the whole window is downtime), and home to `start` by 335 s.
pub fn day() -> Vec<Task> {
    let task = |name: &str, at: [f64; 2], start_s: f64| Task {
        name: name.into(),
        at,
        start_s,
        duration_s: 5.0,
    };
    vec![
        task("goal1", [-2.0, 4.0], 75.0),
        task("goal2", [6.0, -7.0], 165.0),
        task("goal2-again", [6.0, -7.0], 245.0),
        task("home", [-8.0, -8.0], 335.0),
    ]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_demo_day_is_valid_with_a_round_trip() {
        let day = day();
        assert_eq!(check(&day), Ok(()));
        assert!(day.len() >= 4);
        assert!(day.windows(2).any(|w| w[0].at == w[1].at), "a round trip");
    }

    #[test]
    fn the_builtin_day_is_valid_and_overlaps_are_refused() {
        assert_eq!(check(&builtin()), Ok(()));
        let mut tasks = builtin();
        tasks[1].start_s = 77.0; // goal1 runs until 80 s
        assert!(matches!(check(&tasks), Err(TaskError::Bad { .. })));
        assert_eq!(check(&[]), Err(TaskError::Empty));
        let mut tasks = builtin();
        tasks[0].at = [f64::NAN, 0.0];
        assert!(check(&tasks).is_err());
    }
}
