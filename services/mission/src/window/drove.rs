//! What a driven mission teaches the time model.
//!
//! **Replaced missions teach too.** A window's robot is replanned often (slack, behind,
//! the curious plan asked as it set off), so the mission that arrives is often the
//! last few metres of the window's driving; learning only from arrivals left the
//! calibration a few short drives a window, and the prior (Table I, worth
//! `prior_distance_m`) outweighed them. So the part of a replaced mission the robot
//! drove is learned as well. Only a mission the robot was following normally teaches:
//! replaced for slack, for being behind, for lateness, at the last safe moment, or by
//! the plan asked as it set off (or arrived); not one it was held on, pushed off,
//! stuck on or recovering on (that time is not driving), and not when the robot is more than
//! [`MAX_LEARNED_OFF_ROUTE_M`] from the route or drove less than
//! [`MIN_LEARNED_DRIVE_M`] of it.
//!
//! **Where and when a drive begins and ends.** A drive runs from the route's point
//! nearest the robot when the route was sent to its point nearest the robot at the end
//! (not from the route's first point: a replan's route starts where the robot was
//! expected to be when the plan came, and a plan that came early or late leaves the
//! robot short of that point or past it). It is timed between the estimates that put
//! the robot there, by their own times (`WindowEvent::Estimate::time_s`): what is
//! heard comes late by a lag that is not driving, and at a clock ten times wall time a
//! tenth of a second of lag is a second of a drive. An arrival is learned the same way,
//! up to the robot's last estimate (the controller's status that it arrived is heard
//! later still; the arrival margin, which is about the window's time, learns from
//! that, from the route's sending). A robot still within [`STANDING_M`] of where its
//! route was sent has not begun to drive it (the mission is on its way, or it turns
//! toward the path, a turn Eq. 2's Σθ does not count): the drive is timed from its
//! last estimate there. A route that starts where a moving robot was is not timed at
//! all ([`route_teaches`]).

use super::events::DrivenMission;
use super::state::Drive;
use super::straight;
use crate::calibration::path_measure;
use crate::path::distance;
use crate::watch::Reason;

/// The least length of a replaced mission the time model learns from, metres: on a
/// shorter one the time the mission took to reach the robot weighs more than driving.
pub const MIN_LEARNED_DRIVE_M: f64 = 1.0;

/// The farthest the robot may be from the replaced route for its driven part to be
/// learned, metres: farther, the route does not say what it drove.
pub const MAX_LEARNED_OFF_ROUTE_M: f64 = 1.0;

/// The most replaced missions a window learns from (limit `max_learned_drives`): a
/// window replans at most `max_replans` times, but going straight and recovering are
/// not counted there.
pub const MAX_LEARNED_DRIVES: usize = 64;

/// Whether a route sent for `reason` can be timed from its sending: a window's first
/// route (the robot stands at its start) and the routes asked from where the robot
/// will be when they come (slack, behind, set-off, map changed), which it drives into. A route that
/// starts where a moving robot was (straight to the task, after being stuck or pushed
/// off) is reached only after the robot drove on along its old one while the mission
/// travelled: seconds at a fast clock, on what is often a window's last short drive.
pub(super) fn route_teaches(reason: Reason) -> bool {
    matches!(
        reason,
        Reason::Slack | Reason::Behind | Reason::SetOff | Reason::MapChanged
    )
}

/// How far from where its route was sent the robot is still standing, metres.
pub const STANDING_M: f64 = 0.05;

/// Whether a mission replaced for `reason` was being driven normally until then.
pub(super) fn teaches(reason: Reason) -> bool {
    matches!(
        reason,
        Reason::Slack
            | Reason::Behind
            | Reason::EtaSlipped
            | Reason::LastSafeMoment
            | Reason::SetOff
            | Reason::MapChanged
    )
}

/// An estimate at `position` at `at_s`: while the robot stands where its route was
/// sent, the drive is timed from now.
pub(super) fn still_at_start(drive: &mut Drive, position: [f64; 2], at_s: f64) {
    let (start, _) = drive.sent_here;
    if distance(position, start) <= STANDING_M {
        drive.sent_here = (start, at_s);
    }
}

/// The index of `path`'s point nearest `here` among those from `from` on, if it is
/// within [`MAX_LEARNED_OFF_ROUTE_M`].
fn on_route(path: &[[f64; 2]], from: usize, here: [f64; 2]) -> Option<usize> {
    let nearest = from + straight::nearest(path.get(from..)?, here)?;
    (distance(path[nearest], here) <= MAX_LEARNED_OFF_ROUTE_M).then_some(nearest)
}

/// The part of `path` a robot drives from `sent_here`, where it was when the path was
/// sent: from the path's point nearest it on (the whole path when it is farther than
/// [`MAX_LEARNED_OFF_ROUTE_M`]).
pub(super) fn from_where_sent(path: &[[f64; 2]], sent_here: [f64; 2]) -> &[[f64; 2]] {
    &path[on_route(path, 0, sent_here).unwrap_or(0)..]
}

/// The part of `path` the robot drove from `sent_here` (where it was when the path
/// was sent, at its time) to `here` (where it is now, at its time), and the time it
/// took. None when it is not worth learning from (see the module).
pub(super) fn driven_part(
    path: &[[f64; 2]],
    (sent_here, sent_at_s): ([f64; 2], f64),
    (here, here_at_s): ([f64; 2], f64),
) -> Option<DrivenMission> {
    let start = on_route(path, 0, sent_here)?;
    let end = on_route(path, start, here)?;
    let driven = path[start..=end].to_vec();
    let took_s = here_at_s - sent_at_s;
    let (d, _) = path_measure(&driven);
    (d >= MIN_LEARNED_DRIVE_M && took_s > 0.0 && took_s.is_finite()).then_some(DrivenMission {
        path: driven,
        took_s,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    const PATH: [[f64; 2]; 4] = [[0.0, 0.0], [1.0, 0.0], [2.0, 0.0], [2.0, 1.0]];

    #[test]
    fn the_driven_part_runs_between_the_points_nearest_the_robot() {
        let drove = driven_part(&PATH, ([0.1, 0.0], 3.0), ([1.9, 0.2], 7.0)).expect("learned");
        assert_eq!(drove.path, PATH[..3].to_vec());
        assert_eq!(drove.took_s, 4.0);
        let drove = driven_part(&PATH, ([0.9, 0.1], 3.0), ([2.1, 0.9], 7.0)).expect("learned");
        assert_eq!(drove.path, PATH[1..].to_vec());
        assert_eq!(from_where_sent(&PATH, [1.1, 0.0]), &PATH[1..]);
        assert_eq!(from_where_sent(&PATH, [5.0, 5.0]), &PATH[..]);
    }

    #[test]
    fn too_short_off_the_route_or_timeless_drives_teach_nothing() {
        let sent = ([0.0, 0.0], 3.0);
        assert_eq!(driven_part(&PATH, sent, ([0.4, 0.0], 7.0)), None);
        assert_eq!(driven_part(&PATH, sent, ([2.0, -1.5], 7.0)), None);
        assert_eq!(
            driven_part(&PATH, ([-2.0, 0.0], 3.0), ([2.0, 0.0], 7.0)),
            None
        );
        assert_eq!(driven_part(&PATH, sent, ([2.0, 0.0], 3.0)), None);
        assert_eq!(driven_part(&[], sent, ([2.0, 0.0], 7.0)), None);
    }

    #[test]
    fn only_a_normally_driven_mission_teaches() {
        let taught: Vec<Reason> = Reason::ALL.into_iter().filter(|r| teaches(*r)).collect();
        assert_eq!(
            taught,
            [
                Reason::EtaSlipped,
                Reason::Slack,
                Reason::Behind,
                Reason::LastSafeMoment,
                Reason::SetOff,
                Reason::MapChanged
            ]
        );
    }
}
