//! The executives a batch of days compares, each a set of switches over one loop.

use roam_controller::params::Follow;
use serde::Serialize;

/// One executive.
///
/// - `today`: the executive that landed before issue 14's item 7: paper 000's Table I
///   time model throughout (v_lin 2.0 s/m, v_ang 1.0 s/rad), waypoints thinned to
///   mutually visible points about 1 m apart driven one by one (`follow: waypoints`),
///   no slack rule, every window planned at its start, the static information map, no
///   PEB cost.
/// - `new`: the time model calibrated from each arrived mission
///   ([`roam_mission::calibration::Calibration::add_planned`]), every turn of the plan sent
///   ([`roam_mission::path::mission_waypoints`]) and followed as a path, the slack rule
///   ([`roam_mission::watch`]), the next window planned during the task, the arrival margin
///   and the behind rule, the PEB cost (W_loc) and the change coupling (module
///   [`super::planning`]).
/// - `new_no_change`, `new_no_peb`: `new` without one coupling, so that each one's
///   effect shows alone.
/// - `shortest`: the shortest path in every window (the information ratio's baseline),
///   followed as a path.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Variant {
    Today,
    New,
    NewNoChange,
    NewNoPeb,
    Shortest,
}

/// What a variant switches on.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Settings {
    /// Plans use the fitted time model; `false`: Table I.
    pub calibrate: bool,
    /// How the controller follows the mission, and so how a plan becomes waypoints.
    pub follow: Follow,
    /// The slack rule replans curious paths when the robot will be early.
    pub slack: bool,
    /// The next window is planned while the robot does its task.
    pub preplan: bool,
    /// The PEB cost's W_loc (0: off).
    pub w_loc: f64,
    /// Plan on the static map combined with the mapper's change probability.
    pub change: bool,
    /// Ask for curious plans at all (`false`: the shortest path always).
    pub curious: bool,
    /// Plans leave the executive's arrival margin unspent ([`roam_mission::margin`]) and the
    /// behind rule replans when the robot falls behind its plan ([`roam_mission::watch`]).
    pub arrival_guard: bool,
}

impl Variant {
    /// Every variant, in the order the report lists them.
    pub const ALL: [Variant; 5] = [
        Variant::Today,
        Variant::New,
        Variant::NewNoChange,
        Variant::NewNoPeb,
        Variant::Shortest,
    ];

    pub fn name(self) -> &'static str {
        match self {
            Variant::Today => "today",
            Variant::New => "new",
            Variant::NewNoChange => "new_no_change",
            Variant::NewNoPeb => "new_no_peb",
            Variant::Shortest => "shortest",
        }
    }

    /// The variant called `name` (as [`Variant::name`] spells it).
    pub fn parse(name: &str) -> Option<Variant> {
        Variant::ALL.into_iter().find(|v| v.name() == name)
    }

    /// Its switches, with `w_loc` the PEB cost's weight where it is on.
    pub fn settings(self, w_loc: f64) -> Settings {
        let new = Settings {
            calibrate: true,
            follow: Follow::Path,
            slack: true,
            preplan: true,
            w_loc,
            change: true,
            curious: true,
            arrival_guard: true,
        };
        match self {
            Variant::Today => Settings {
                calibrate: false,
                follow: Follow::Waypoints,
                slack: false,
                preplan: false,
                w_loc: 0.0,
                change: false,
                curious: true,
                arrival_guard: false,
            },
            Variant::New => new,
            Variant::NewNoChange => Settings {
                change: false,
                ..new
            },
            Variant::NewNoPeb => Settings { w_loc: 0.0, ..new },
            Variant::Shortest => Settings {
                calibrate: false,
                slack: false,
                preplan: false,
                w_loc: 0.0,
                change: false,
                curious: false,
                arrival_guard: false,
                ..new
            },
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_round_trip_and_the_ablations_differ_from_new_in_one_switch() {
        for v in Variant::ALL {
            assert_eq!(Variant::parse(v.name()), Some(v));
        }
        assert_eq!(Variant::parse("tomorrow"), None);
        let new = Variant::New.settings(2000.0);
        let no_change = Variant::NewNoChange.settings(2000.0);
        let no_peb = Variant::NewNoPeb.settings(2000.0);
        assert!(new.change && !no_change.change);
        assert_eq!(
            Settings {
                change: true,
                ..no_change
            },
            new
        );
        assert_eq!((new.w_loc, no_peb.w_loc), (2000.0, 0.0));
        assert_eq!(
            Settings {
                w_loc: 2000.0,
                ..no_peb
            },
            new
        );
        let today = Variant::Today.settings(2000.0);
        assert!(!today.calibrate && !today.slack && !today.preplan && today.w_loc == 0.0);
        assert_eq!(today.follow, Follow::Waypoints);
        assert!(!Variant::Shortest.settings(2000.0).curious);
    }
}
