//! A ROS 2 action server's goals, without Zenoh: which goals it knows, their states and
//! results, and what a cancel request names (design.ros2.org's "Actions" article, as
//! rcl_action implements it). The node's ComputePathToPose server keeps one table.

use std::collections::BTreeMap;
use std::time::{Duration, Instant};

use crate::msg::{
    CancelGoalRequest, CancelGoalResponse, ComputePathResult, GoalInfo, GoalState, GoalStatus,
    GoalStatusArray, Time, Uuid, CANCEL_GOAL_TERMINATED, CANCEL_NONE, CANCEL_REJECTED,
    CANCEL_UNKNOWN_GOAL_ID,
};

/// One goal: when it was accepted, its state, and its result once final.
#[derive(Debug, Clone)]
pub struct Goal {
    pub stamp: Time,
    pub state: GoalState,
    pub result: ComputePathResult,
    finished: Option<Instant>,
}

/// The goals of one action server, bounded.
#[derive(Debug)]
pub struct GoalTable {
    goals: BTreeMap<Uuid, Goal>,
    /// Goals not yet final; a goal beyond them is not accepted.
    pub max_running: usize,
    /// Goals remembered; the oldest finished one is forgotten first.
    pub max_goals: usize,
    /// How long a final result is kept.
    pub keep: Duration,
}

impl GoalTable {
    pub fn new(max_running: usize, max_goals: usize, keep: Duration) -> GoalTable {
        GoalTable {
            goals: BTreeMap::new(),
            max_running: max_running.max(1),
            max_goals: max_goals.max(max_running.max(1) + 1),
            keep,
        }
    }

    /// Accepts goal `id` (executing from `stamp`), or says why not: its id is taken, or
    /// `max_running` goals are running. Forgets results older than `keep` and, when
    /// full, the oldest finished goal.
    pub fn admit(&mut self, id: Uuid, stamp: Time, now: Instant) -> Result<(), String> {
        let keep = self.keep;
        self.goals
            .retain(|_, g| g.finished.is_none_or(|at| now.duration_since(at) < keep));
        if self.goals.contains_key(&id) {
            return Err("a goal with this id is already known; send a fresh UUID".to_owned());
        }
        let running = self.goals.values().filter(|g| g.finished.is_none()).count();
        if running >= self.max_running {
            return Err(format!(
                "{} goals are being planned; send it again in a moment",
                self.max_running
            ));
        }
        while self.goals.len() >= self.max_goals {
            let oldest = self
                .goals
                .iter()
                .filter_map(|(id, g)| g.finished.map(|at| (at, *id)))
                .min();
            match oldest {
                Some((_, oldest)) => self.goals.remove(&oldest),
                None => break,
            };
        }
        self.goals.insert(
            id,
            Goal {
                stamp,
                state: GoalState::Executing,
                result: ComputePathResult::default(),
                finished: None,
            },
        );
        Ok(())
    }

    /// Ends goal `id` with `state` and `result`; `false` if it is unknown or ended.
    pub fn finish(
        &mut self,
        id: &Uuid,
        state: GoalState,
        result: ComputePathResult,
        now: Instant,
    ) -> bool {
        match self.goals.get_mut(id) {
            Some(goal) if goal.finished.is_none() => {
                goal.state = state;
                goal.result = result;
                goal.finished = Some(now);
                true
            }
            _ => false,
        }
    }

    pub fn get(&self, id: &Uuid) -> Option<&Goal> {
        self.goals.get(id)
    }

    /// Every goal's state, oldest first: the `_action/status` message.
    pub fn status(&self) -> GoalStatusArray {
        let mut status_list: Vec<GoalStatus> = self
            .goals
            .iter()
            .map(|(id, goal)| GoalStatus {
                goal_info: GoalInfo {
                    goal_id: *id,
                    stamp: goal.stamp,
                },
                status: goal.state as i8,
            })
            .collect();
        status_list.sort_by_key(|s| s.goal_info.stamp.as_nanos());
        GoalStatusArray { status_list }
    }

    /// The running goals a cancel request names, set canceling. The rules: a zero id
    /// and a zero stamp name every goal; a zero id and a stamp, every goal accepted at or
    /// before it; an id, that goal, and with a stamp also those at or before it. When
    /// none is canceling, the code says why: the goal is unknown, it has ended, or
    /// (a cancel by stamp or of all) nothing was running.
    pub fn cancel(&mut self, request: &CancelGoalRequest) -> CancelGoalResponse {
        let info = request.goal_info;
        let any_id = info.goal_id == Uuid::default();
        let by_stamp = info.stamp != Time::default();
        let mut canceling = Vec::new();
        for (id, goal) in self.goals.iter_mut() {
            let named = (any_id && !by_stamp) || (!any_id && *id == info.goal_id);
            let before = by_stamp && goal.stamp.as_nanos() <= info.stamp.as_nanos();
            if (named || before) && !goal.state.is_terminal() {
                goal.state = GoalState::Canceling;
                canceling.push(GoalInfo {
                    goal_id: *id,
                    stamp: goal.stamp,
                });
            }
        }
        let return_code = if !canceling.is_empty() {
            CANCEL_NONE
        } else if any_id {
            CANCEL_REJECTED
        } else if self.goals.contains_key(&info.goal_id) {
            CANCEL_GOAL_TERMINATED
        } else {
            CANCEL_UNKNOWN_GOAL_ID
        };
        CancelGoalResponse {
            return_code,
            goals_canceling: canceling,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn id(n: u8) -> Uuid {
        Uuid { uuid: [n; 16] }
    }

    fn at(sec: i32) -> Time {
        Time { sec, nanosec: 0 }
    }

    fn cancel(goal: Uuid, stamp: Time) -> CancelGoalRequest {
        CancelGoalRequest {
            goal_info: GoalInfo {
                goal_id: goal,
                stamp,
            },
        }
    }

    #[test]
    fn ids_are_unique_and_running_goals_bounded() {
        let now = Instant::now();
        let mut table = GoalTable::new(2, 8, Duration::from_secs(60));
        assert!(table.admit(id(1), at(1), now).is_ok());
        assert!(table
            .admit(id(1), at(2), now)
            .expect_err("refused")
            .contains("fresh UUID"));
        assert!(table.admit(id(2), at(2), now).is_ok());
        assert!(table
            .admit(id(3), at(3), now)
            .expect_err("refused")
            .contains("2 goals"));
        assert!(table.finish(&id(1), GoalState::Succeeded, Default::default(), now));
        assert!(!table.finish(&id(1), GoalState::Aborted, Default::default(), now));
        assert_eq!(
            table.get(&id(1)).map(|g| g.state),
            Some(GoalState::Succeeded)
        );
        assert!(table.admit(id(3), at(3), now).is_ok());
    }

    #[test]
    fn results_expire_and_the_oldest_finished_goes_first() {
        let now = Instant::now();
        let mut table = GoalTable::new(1, 3, Duration::from_secs(60));
        for n in 1..=3 {
            table.admit(id(n), at(n.into()), now).expect("admit");
            table.finish(&id(n), GoalState::Succeeded, Default::default(), now);
        }
        table.admit(id(4), at(4), now).expect("admit");
        assert!(
            table.get(&id(1)).is_none(),
            "the oldest finished is forgotten"
        );
        assert!(table.get(&id(2)).is_some());
        let later = now + Duration::from_secs(61);
        table.finish(&id(4), GoalState::Aborted, Default::default(), later);
        table.admit(id(5), at(5), later).expect("admit");
        assert!(table.get(&id(2)).is_none() && table.get(&id(3)).is_none());
        assert!(
            table.get(&id(4)).is_some(),
            "kept for `keep` after it ended"
        );
        let states: Vec<i8> = table
            .status()
            .status_list
            .iter()
            .map(|s| s.status)
            .collect();
        assert_eq!(
            states,
            [GoalState::Aborted as i8, GoalState::Executing as i8]
        );
    }

    #[test]
    fn a_cancel_names_goals_by_id_by_stamp_or_all() {
        let now = Instant::now();
        let mut table = GoalTable::new(8, 16, Duration::from_secs(60));
        for n in 1..=4 {
            table.admit(id(n), at(n.into()), now).expect("admit");
        }
        table.finish(&id(4), GoalState::Succeeded, Default::default(), now);
        let by_id = table.cancel(&cancel(id(1), Time::default()));
        assert_eq!(by_id.return_code, CANCEL_NONE);
        assert_eq!(by_id.goals_canceling.len(), 1);
        assert_eq!(
            table.get(&id(1)).map(|g| g.state),
            Some(GoalState::Canceling)
        );
        let by_stamp = table.cancel(&cancel(Uuid::default(), at(2)));
        let ids: Vec<Uuid> = by_stamp.goals_canceling.iter().map(|g| g.goal_id).collect();
        assert_eq!(
            ids,
            [id(1), id(2)],
            "goals 1 and 2 were accepted at or before 2 s"
        );
        assert_eq!(
            table.cancel(&cancel(id(4), Time::default())).return_code,
            CANCEL_GOAL_TERMINATED
        );
        assert_eq!(
            table.cancel(&cancel(id(9), Time::default())).return_code,
            CANCEL_UNKNOWN_GOAL_ID
        );
        let all = table.cancel(&cancel(Uuid::default(), Time::default()));
        assert_eq!(all.goals_canceling.len(), 3, "1, 2 and 3 are still running");
        table.finish(&id(1), GoalState::Canceled, Default::default(), now);
        table.finish(&id(2), GoalState::Canceled, Default::default(), now);
        table.finish(&id(3), GoalState::Canceled, Default::default(), now);
        assert_eq!(
            table
                .cancel(&cancel(Uuid::default(), Time::default()))
                .return_code,
            CANCEL_REJECTED
        );
    }
}
