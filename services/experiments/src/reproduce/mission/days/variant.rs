//! The configurations a batch of days compares. Each is an [`ExecutiveConfig`] (what
//! `roam mission --config` runs live) and whether the planner couples the mapper's
//! change layer into its information map (`roam planner`'s `change_layer`), so every
//! row of the report is something a user can run, never a second program.

use roam_mission::config::ExecutiveConfig;
use serde::Serialize;

/// One configuration.
///
/// - `executive`: roam's executive as it ships (`ExecutiveConfig::default()`): the time
///   model calibrated from each arrived mission, the arrival margin sized from its
///   errors, the slack, behind and last-safe-moment rules, plans made ahead, holds
///   recovered, the PEB cost (W_loc) and the change coupling on the planner.
/// - `no_change`, `no_peb`: `executive` without one coupling, so that each one's effect
///   shows alone.
/// - `anytime`: `executive` planning with the planner's anytime portfolio (the greedy
///   route, then the GA seeded with it) instead of Model I's GA: what the portfolio
///   is worth in the day.
/// - `plain`: paper 000's planner alone, as an executive without roam's rules would use
///   it ([`ExecutiveConfig::plain`]): Table I throughout, one plan at each window's
///   start, no margin, no slack or behind rule, no recovery, no PEB cost, no change
///   coupling.
/// - `fastest_path`: the fastest path in every window, what a user would drive without
///   curiosity (the information ratio's baseline).
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Variant {
    Plain,
    Executive,
    NoChange,
    NoPeb,
    FastestPath,
    Anytime,
}

impl Variant {
    /// Every variant, in the order the report lists them.
    pub const ALL: [Variant; 6] = [
        Variant::Plain,
        Variant::Executive,
        Variant::NoChange,
        Variant::NoPeb,
        Variant::FastestPath,
        Variant::Anytime,
    ];

    /// The variants a batch runs unless told which: [`Variant::ALL`] but its last,
    /// `anytime`, a question asked once (services/mission/README.md, "The anytime
    /// portfolio in the day").
    pub const DEFAULT: &[Variant] = Variant::ALL.split_at(5).0;

    pub fn name(self) -> &'static str {
        match self {
            Variant::Plain => "plain",
            Variant::Executive => "executive",
            Variant::NoChange => "no_change",
            Variant::NoPeb => "no_peb",
            Variant::Anytime => "anytime",
            Variant::FastestPath => "fastest_path",
        }
    }

    /// The variant called `name` (as [`Variant::name`] spells it).
    pub fn parse(name: &str) -> Option<Variant> {
        Variant::ALL.into_iter().find(|v| v.name() == name)
    }

    /// The executive's configuration: `base` (the day's robot, tasks, generations and
    /// seed) with this variant's rules, `w_loc` the PEB cost where it is on.
    pub fn config(self, base: ExecutiveConfig, w_loc: f64) -> ExecutiveConfig {
        let executive = ExecutiveConfig {
            w_loc: Some(w_loc),
            ..base
        };
        match self {
            Variant::Executive | Variant::NoChange => executive,
            Variant::NoPeb => ExecutiveConfig {
                w_loc: None,
                ..executive
            },
            Variant::Anytime => ExecutiveConfig {
                model: roam_proto::planner::PlannerModel::Anytime,
                ..executive
            },
            Variant::Plain => executive.plain(),
            Variant::FastestPath => executive.fastest_path_only(),
        }
    }

    /// The planner couples the change layer into its information map.
    pub fn change_coupling(self) -> bool {
        matches!(self, Variant::Executive | Variant::NoPeb | Variant::Anytime)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use roam_proto::planner::PlannerModel;

    #[test]
    fn names_round_trip_and_the_ablations_differ_from_the_executive_in_one_setting() {
        for v in Variant::ALL {
            assert_eq!(Variant::parse(v.name()), Some(v));
            assert_eq!(v.config(ExecutiveConfig::default(), 2000.0).check(), Ok(()));
        }
        assert_eq!(Variant::parse("new"), None);
        let base = ExecutiveConfig::default;
        let executive = Variant::Executive.config(base(), 2000.0);
        assert_eq!(Variant::NoChange.config(base(), 2000.0), executive);
        assert!(Variant::Executive.change_coupling() && !Variant::NoChange.change_coupling());
        let no_peb = Variant::NoPeb.config(base(), 2000.0);
        assert_eq!(
            ExecutiveConfig {
                w_loc: Some(2000.0),
                ..no_peb
            },
            executive
        );
        let plain = Variant::Plain.config(base(), 2000.0);
        assert!(!plain.calibrate && !plain.plan_ahead && plain.w_loc.is_none());
        assert_eq!(
            Variant::FastestPath.config(base(), 2000.0).model,
            PlannerModel::Shortest
        );
        assert_eq!(executive.model, PlannerModel::Model1);
        assert_eq!(
            ExecutiveConfig {
                model: PlannerModel::Model1,
                ..Variant::Anytime.config(base(), 2000.0)
            },
            executive
        );
        assert_eq!(plain.model, PlannerModel::Model1);
    }
}
