//! A robot the controller's PEB guard holds (paper 002's uncertainty, roam's guard): the
//! window counts the hold and, after `hold_patience_s`, drives the robot back along its
//! own track past its last fix with a recovery mission (which the guard lets through),
//! then goes straight to the task from there (`heard.rs`).

use super::events::{Now, WindowAction};
use super::setup::{MAX_RECOVERIES, RECOVERY_BACK_M};
use super::state::{DowntimeWindow, Phase};
use super::straight;
use crate::path::mission_waypoints;
use crate::watch::Replanned;

impl DowntimeWindow<'_> {
    /// A status that the PEB guard holds the robot on the current mission.
    pub(super) fn on_held(&mut self, now: Now) -> Vec<WindowAction> {
        let rules = self.setup.rules;
        let spacing = self.setup.waypoint_spacing_m;
        let Phase::Driving(drive) = &mut self.phase else {
            return Vec::new();
        };
        let since = *drive.held_since_s.get_or_insert_with(|| {
            drive.holds += 1;
            now.mission_s
        });
        let held_s = now.mission_s - since;
        let spent = drive.recoveries >= MAX_RECOVERIES;
        if !rules.recover || drive.recovering || spent || held_s < rules.hold_patience_s {
            return Vec::new();
        }
        let back = straight::back_along(&self.driven, self.last_fix, RECOVERY_BACK_M);
        let waypoints = mission_waypoints(&back, spacing);
        let mut actions = self.forget_drive_ask();
        let Phase::Driving(drive) = &mut self.phase else {
            return actions;
        };
        drive.recovering = true;
        drive.recoveries += 1;
        drive.held_s += held_s;
        drive.held_since_s = None;
        drive
            .watch
            .replanned(back.clone(), Replanned::Resend, now.mission_s, now.wall_s);
        drive.path = back;
        drive.waypoints = waypoints.clone();
        let mission = self.ids.next(waypoints, true);
        drive.mission = mission.id.clone();
        actions.push(WindowAction::Recovering { held_s });
        actions.push(WindowAction::Drive(mission));
        actions
    }
}
