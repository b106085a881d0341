//! What the fleet's week compares. Each variant is the executive's configuration
//! ([`ExecutiveConfig`], what each robot's `roam mission` runs) and what the planner
//! plans on (its information map: the static one, or the mapper's news coupled into
//! it, `roam planner`'s `coupling: news`), so every row is something a fleet can run.
//!
//! - `tasks_only`: the fastest path to each task, then wait there: a fleet without
//!   roam's curiosity (the executive's other rules kept: its margin, its recovery from a
//!   PEB hold, its replans when blocked).
//! - `patrol`: each idle robot on a fixed loop through every aisle, as far as its
//!   window allows, back on time ([`super::patrol`]): what an operator would run.
//! - `independent`: each robot curious on the static information (paper 000 Model I,
//!   the PEB cost on), nothing shared: roam's single-robot executive, ten times.
//! - `news`: roam for a fleet: the planner on interest × the probability of news, from
//!   the fleet's shared map, with the cells on the other robots' plans counted as seen
//!   at their times ([`roam_mapper::news`]).
//! - `news_no_sharing`, `news_no_reservations`, `news_no_rates`: `news` with one part
//!   off: each robot's news from its own observations only (and no reservations, which
//!   need the others' plans); the others' plans not counted; the rates not learnt (a
//!   prior so strong that no event moves it: news is then how long nobody looked).
//! - `news_map_replans`: `news` with each executive following what the fleet believes
//!   occupied now (`obstacles_layer: occupied_now`): a route a pallet lands on is
//!   replanned round it at once (`map_changed`, `roam_mission::window`), where `news`
//!   drives on until the robot is stuck. Not `news`'s default: two shifts showed no
//!   effect through the fleet's chaos (experiments README, "Map-change replans in the
//!   fleet").

use roam_mapper::news::DEFAULT_NEWS_PRIOR;
use roam_mapper::prior::RatePrior;
use roam_mission::config::ExecutiveConfig;
use roam_proto::planner::PlannerModel;
use serde::Serialize;

/// One configuration of the fleet.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum FleetVariant {
    TasksOnly,
    Patrol,
    Independent,
    News,
    NewsNoSharing,
    NewsNoReservations,
    NewsNoRates,
    NewsMapReplans,
}

/// What curious plans are made on.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Planning {
    /// No curious plans: the fastest path.
    Fastest,
    /// The patrol loop.
    Patrol,
    /// The static information map.
    Static,
    /// Interest × P_news.
    News {
        shared: bool,
        reservations: bool,
        prior: RatePrior,
    },
}

/// The prior that stands for "rates not learnt": the default's mean rate, a million
/// times as sure.
const RATES_OFF: RatePrior = RatePrior {
    alpha: DEFAULT_NEWS_PRIOR.alpha * 1e6,
    beta_s: DEFAULT_NEWS_PRIOR.beta_s * 1e6,
};

impl FleetVariant {
    pub const ALL: [FleetVariant; 8] = [
        FleetVariant::TasksOnly,
        FleetVariant::Patrol,
        FleetVariant::Independent,
        FleetVariant::News,
        FleetVariant::NewsNoSharing,
        FleetVariant::NewsNoReservations,
        FleetVariant::NewsNoRates,
        FleetVariant::NewsMapReplans,
    ];

    /// The variants a week runs unless told which: [`FleetVariant::ALL`] but its last,
    /// `news_map_replans`, an option still being measured (experiments README,
    /// "Map-change replans in the fleet").
    pub const DEFAULT: &[FleetVariant] = FleetVariant::ALL.split_at(7).0;

    pub fn name(self) -> &'static str {
        match self {
            FleetVariant::TasksOnly => "tasks_only",
            FleetVariant::Patrol => "patrol",
            FleetVariant::Independent => "independent",
            FleetVariant::News => "news",
            FleetVariant::NewsNoSharing => "news_no_sharing",
            FleetVariant::NewsNoReservations => "news_no_reservations",
            FleetVariant::NewsNoRates => "news_no_rates",
            FleetVariant::NewsMapReplans => "news_map_replans",
        }
    }

    pub fn parse(name: &str) -> Option<FleetVariant> {
        FleetVariant::ALL.into_iter().find(|v| v.name() == name)
    }

    /// The executive's configuration: `base` (the robot, its week of tasks, the
    /// generations, the seed) with this variant's rules; `w_loc` the PEB cost and
    /// `curious` the planner's model for the curious variants.
    pub fn config(
        self,
        base: ExecutiveConfig,
        w_loc: f64,
        curious: PlannerModel,
    ) -> ExecutiveConfig {
        match self {
            FleetVariant::TasksOnly => ExecutiveConfig {
                model: roam_proto::planner::PlannerModel::Shortest,
                w_loc: None,
                ..base
            },
            FleetVariant::Patrol => ExecutiveConfig {
                w_loc: None,
                ..base
            },
            FleetVariant::NewsMapReplans => ExecutiveConfig {
                obstacles_layer: Some(roam_proto::mapper::OCCUPIED_NOW_LAYER.to_owned()),
                ..FleetVariant::News.config(base, w_loc, curious)
            },
            _ => ExecutiveConfig {
                model: curious,
                w_loc: Some(w_loc),
                ..base
            },
        }
    }

    pub fn planning(self) -> Planning {
        let news = |shared, reservations, prior| Planning::News {
            shared,
            reservations,
            prior,
        };
        match self {
            FleetVariant::TasksOnly => Planning::Fastest,
            FleetVariant::Patrol => Planning::Patrol,
            FleetVariant::Independent => Planning::Static,
            FleetVariant::News => news(true, true, DEFAULT_NEWS_PRIOR),
            FleetVariant::NewsNoSharing => news(false, false, DEFAULT_NEWS_PRIOR),
            FleetVariant::NewsNoReservations => news(true, false, DEFAULT_NEWS_PRIOR),
            FleetVariant::NewsNoRates => news(true, true, RATES_OFF),
            FleetVariant::NewsMapReplans => news(true, true, DEFAULT_NEWS_PRIOR),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_round_trip_and_each_part_of_news_is_off_alone() {
        for v in FleetVariant::ALL {
            assert_eq!(FleetVariant::parse(v.name()), Some(v));
            assert_eq!(
                v.config(ExecutiveConfig::default(), 2000.0, PlannerModel::Greedy)
                    .check(),
                Ok(())
            );
        }
        assert_eq!(
            FleetVariant::TasksOnly
                .config(ExecutiveConfig::default(), 2000.0, PlannerModel::Greedy)
                .model,
            PlannerModel::Shortest
        );
        let Planning::News {
            shared,
            reservations,
            prior,
        } = FleetVariant::News.planning()
        else {
            panic!("news plans on news");
        };
        assert!(shared && reservations && prior == DEFAULT_NEWS_PRIOR);
        for (v, differs) in [
            (FleetVariant::NewsNoReservations, "reservations"),
            (FleetVariant::NewsNoRates, "prior"),
        ] {
            let Planning::News {
                shared: s,
                reservations: r,
                prior: p,
            } = v.planning()
            else {
                panic!("{differs}");
            };
            assert_eq!(
                [s == shared, r == reservations, p == prior]
                    .iter()
                    .filter(|x| !**x)
                    .count(),
                1,
                "{differs}"
            );
        }
        // With map replans: the news's config but for the layer followed.
        let base = ExecutiveConfig::default;
        let news = FleetVariant::News.config(base(), 2000.0, PlannerModel::Greedy);
        let map = FleetVariant::NewsMapReplans.config(base(), 2000.0, PlannerModel::Greedy);
        assert!(news.obstacles_layer.is_none() && map.obstacles_layer.is_some());
        assert_eq!(
            ExecutiveConfig {
                obstacles_layer: None,
                ..map
            },
            news
        );
        assert_eq!(
            FleetVariant::NewsMapReplans.planning(),
            FleetVariant::News.planning()
        );
        // The strong prior's mean rate is the default's.
        let mean = |p: RatePrior| p.alpha / p.beta_s;
        assert!((mean(RATES_OFF) / mean(DEFAULT_NEWS_PRIOR) - 1.0).abs() < 1e-12);
    }
}
