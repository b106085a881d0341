//! The chaos day's faults and when they strike: a pure function of the seed, so a run
//! can be repeated fault for fault.
//!
//! Every role is killed once (SIGKILL, started again after a delay), the planners are
//! cut off from the router (their link stops carrying anything), the controller is cut
//! off likewise, and one planner is frozen (SIGSTOP, then SIGCONT: a planner that
//! answers slowly). The order is a seeded shuffle; the faults are spread evenly over
//! the day's sim time, each a seeded fraction of its slot late.

use rand::seq::SliceRandom;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use serde::Serialize;

/// What one fault does.
#[derive(Debug, Clone, PartialEq, Eq, Serialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum Fault {
    /// SIGKILL the role's process; start it again `hold_s` later.
    Kill { role: String },
    /// The role's link to the router carries nothing for `hold_s` (its process runs on).
    Partition { link: String },
    /// SIGSTOP the role's process, SIGCONT it `hold_s` later: it answers that much late.
    Freeze { role: String },
}

impl Fault {
    /// The roles whose recovery is measured after the fault ends.
    pub fn roles<'a>(&'a self, links: &'a [(&str, Vec<&str>)]) -> Vec<&'a str> {
        match self {
            Fault::Kill { role } | Fault::Freeze { role } => vec![role.as_str()],
            Fault::Partition { link } => links
                .iter()
                .find(|(name, _)| name == link)
                .map(|(_, roles)| roles.clone())
                .unwrap_or_default(),
        }
    }

    pub fn describe(&self) -> String {
        match self {
            Fault::Kill { role } => format!("kill {role}"),
            Fault::Partition { link } => format!("cut the {link} link"),
            Fault::Freeze { role } => format!("freeze {role}"),
        }
    }
}

/// One fault of the day: when (sim seconds) and for how long (wall seconds).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Scheduled {
    pub at_sim_s: f64,
    pub hold_s: f64,
    pub fault: Fault,
}

/// What a schedule is drawn from.
#[derive(Debug, Clone)]
pub struct ScheduleSpec<'a> {
    /// Every role killed once, by name (`router`, `map-server`, …).
    pub kill: &'a [&'a str],
    /// The links cut, by name.
    pub partitions: &'a [&'a str],
    /// The roles frozen.
    pub freeze: &'a [&'a str],
    /// The sim span the faults are spread over.
    pub from_sim_s: f64,
    pub to_sim_s: f64,
    /// A killed role is started again after a delay drawn from this range, wall seconds.
    pub restart_delay_s: (f64, f64),
    pub partition_s: f64,
    pub freeze_s: f64,
}

/// The day's faults in the order they strike.
pub fn schedule(spec: &ScheduleSpec<'_>, seed: u64) -> Vec<Scheduled> {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let mut faults: Vec<Fault> = spec
        .kill
        .iter()
        .map(|r| Fault::Kill {
            role: (*r).to_owned(),
        })
        .chain(spec.partitions.iter().map(|l| Fault::Partition {
            link: (*l).to_owned(),
        }))
        .chain(spec.freeze.iter().map(|r| Fault::Freeze {
            role: (*r).to_owned(),
        }))
        .collect();
    faults.shuffle(&mut rng);
    let slot = (spec.to_sim_s - spec.from_sim_s) / faults.len().max(1) as f64;
    let (lo, hi) = spec.restart_delay_s;
    faults
        .into_iter()
        .enumerate()
        .map(|(k, fault)| {
            let jitter: f64 = rng.random_range(0.0..0.5);
            let hold_s = match fault {
                Fault::Kill { .. } => lo + (hi - lo) * rng.random::<f64>(),
                Fault::Partition { .. } => spec.partition_s,
                Fault::Freeze { .. } => spec.freeze_s,
            };
            Scheduled {
                at_sim_s: spec.from_sim_s + slot * (k as f64 + jitter),
                hold_s,
                fault,
            }
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn spec() -> ScheduleSpec<'static> {
        ScheduleSpec {
            kill: &["router", "map-server", "planner-a", "sim"],
            partitions: &["planners", "controller"],
            freeze: &["planner-b"],
            from_sim_s: 10.0,
            to_sim_s: 300.0,
            restart_delay_s: (0.5, 2.0),
            partition_s: 12.0,
            freeze_s: 4.0,
        }
    }

    #[test]
    fn every_fault_strikes_once_in_order_within_the_span() {
        let day = schedule(&spec(), 7);
        assert_eq!(day.len(), 7);
        for role in ["router", "map-server", "planner-a", "sim"] {
            let kills = day
                .iter()
                .filter(|s| s.fault == Fault::Kill { role: role.into() })
                .count();
            assert_eq!(kills, 1, "{role}");
        }
        assert!(day.windows(2).all(|w| w[0].at_sim_s < w[1].at_sim_s));
        assert!(day.iter().all(|s| (10.0..300.0).contains(&s.at_sim_s)));
        for s in &day {
            match s.fault {
                Fault::Kill { .. } => assert!((0.5..=2.0).contains(&s.hold_s)),
                Fault::Partition { .. } => assert_eq!(s.hold_s, 12.0),
                Fault::Freeze { .. } => assert_eq!(s.hold_s, 4.0),
            }
        }
    }

    #[test]
    fn the_seed_decides_the_schedule() {
        assert_eq!(schedule(&spec(), 3), schedule(&spec(), 3));
        let orders: std::collections::BTreeSet<Vec<String>> = (0..8)
            .map(|seed| {
                schedule(&spec(), seed)
                    .iter()
                    .map(|s| s.fault.describe())
                    .collect()
            })
            .collect();
        assert!(orders.len() > 1, "eight seeds, one order");
    }

    #[test]
    fn a_partition_measures_every_role_behind_its_link() {
        let links = [("planners", vec!["planner-a", "planner-b"])];
        let cut = Fault::Partition {
            link: "planners".into(),
        };
        assert_eq!(cut.roles(&links), vec!["planner-a", "planner-b"]);
        let kill = Fault::Kill { role: "sim".into() };
        assert_eq!(kill.roles(&links), vec!["sim"]);
    }
}
