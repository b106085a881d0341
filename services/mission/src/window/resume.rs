//! A restarted executive's first window drives on with the route its predecessor was
//! driving (kept in the executive's `resume_file`), instead of starting over on the
//! fastest path and a fresh curious plan: what the predecessor's planning bought is not
//! thrown away, and the robot is not turned round by a new route.
//!
//! Taken only when it is for the window's own task (same name and start), the robot is
//! within [`RESUME_WITHIN_M`] of it, and, for a curious route, its last safe moment has
//! not come: the budget the arrival margin leaves of the time to the task, less two of
//! the rule's periods, still covers what is left of the route from the point nearest
//! the robot (Eq. 2 under the window's time model) or at least the fastest path from
//! there, as the running window would judge it. Otherwise the window begins as without
//! it. The window's report lists `resumed` among its reasons.

use super::events::{Now, WindowAction};
use super::resumed::Resumed;
use super::routes::Route;
use super::setup::SAFE_CHECK_S;
use super::state::{DowntimeWindow, Phase};
use super::straight;
use crate::calibration::path_measure;
use crate::path::off_path_m;
use crate::watch::Reason;

/// A resumed route is taken when the robot is at most this far from it, metres (a
/// robot farther off was moved, or the route is not the one it drove).
pub const RESUME_WITHIN_M: f64 = 1.0;

impl DowntimeWindow<'_> {
    /// The route the robot is driving now, to keep for a successor; `None` before the
    /// first route is sent.
    pub fn driving(&self) -> Option<Resumed> {
        let Phase::Driving(drive) = &self.phase else {
            return None;
        };
        Some(Resumed {
            task: self.setup.task.name.clone(),
            task_start_s: self.setup.task.start_s,
            curious: drive.route_curious,
            points: drive.plans.last()?.clone(),
        })
    }

    /// Begins driving what is left of `resumed`; `None` when it is not this window's,
    /// the robot is off it, or it no longer fits.
    pub(super) fn resume(&mut self, resumed: Resumed, now: Now) -> Option<Vec<WindowAction>> {
        let task = &self.setup.task;
        if resumed.task != task.name || resumed.task_start_s.to_bits() != task.start_s.to_bits() {
            return None;
        }
        if resumed.points.is_empty() || off_path_m(self.here, &resumed.points) > RESUME_WITHIN_M {
            return None;
        }
        let left = straight::route_left(&resumed.points, self.here);
        let points = left.get(1..)?.to_vec();
        let (d, theta) = path_measure(&left);
        let t_eta_s = self.setup.time_model.eta(d, theta);
        let time_left_s = task.start_s - now.mission_s;
        let budget_s = self.margin.budget(time_left_s);
        let fastest = self.fastest_from_here();
        // Judged as the running window judges a curious route at the last safe moment
        // (`check_safe`): it is driven on while the budget of the time left, less two
        // checks' periods, covers the route left or at least the fastest path from
        // here; the window's rules take it from there. A fastest path is driven on.
        let safe_s = self.margin.budget(time_left_s - 2.0 * SAFE_CHECK_S);
        let fits = !resumed.curious
            || safe_s > t_eta_s
            || fastest.as_ref().is_some_and(|f| safe_s > f.t_eta_s);
        if !fits {
            return None;
        }
        let shortest = fastest.map_or_else(|| points.clone(), |r| r.points);
        let route = Route {
            points,
            t_eta_s,
            curious: resumed.curious,
        };
        let mut actions = self.start_driving(route, shortest, budget_s, time_left_s, now);
        if let Phase::Driving(drive) = &mut self.phase {
            drive.reasons.push(Reason::Resumed.name().to_owned());
        }
        actions.insert(
            0,
            WindowAction::Replanned {
                reason: Reason::Resumed,
            },
        );
        Some(actions)
    }
}
