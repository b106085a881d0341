//! Per-robot state for a bounded number of robots.
//!
//! Missions and true positions for any robot name can be put on the stack's keys, by
//! anyone, so the view keeps state for at most a fixed number of robots. When a new
//! robot comes and the roster is full, the robot heard from least recently *that the
//! sim's last status does not name* makes room: a thousand missions for robots that do not
//! exist evict each other, never the sim's own robots. A stack without a sim (every robot
//! unnamed) simply keeps the most recent ones.

use std::collections::BTreeMap;

/// The most robots whose missions are kept, and the most whose driven paths are.
pub const MAX_ROBOTS: usize = 256;

/// State of type `T` for at most `capacity` robots.
#[derive(Debug)]
pub(crate) struct Roster<T> {
    capacity: usize,
    /// A counter that orders the touches: the least is the least recent.
    clock: u64,
    robots: BTreeMap<String, (u64, T)>,
}

/// What [`Roster::touch`] did.
#[derive(Debug, PartialEq, Eq)]
pub(crate) enum Touched {
    /// The robot was already there, or there was room for it.
    Kept,
    /// It took the place of this robot, whose state is gone.
    Evicted(String),
    /// No room: every robot kept is one the sim names and this one is not.
    Refused,
}

impl<T> Roster<T> {
    pub(crate) fn new(capacity: usize) -> Self {
        Roster {
            capacity: capacity.max(1),
            clock: 0,
            robots: BTreeMap::new(),
        }
    }

    /// Marks `robot` as just heard from, making its state with `make` if it is new (see
    /// the module's doc for who makes room). `named` says whether the sim names a robot.
    pub(crate) fn touch(
        &mut self,
        robot: &str,
        named: impl Fn(&str) -> bool,
        make: impl FnOnce() -> T,
    ) -> Touched {
        self.clock += 1;
        if let Some((last, _)) = self.robots.get_mut(robot) {
            *last = self.clock;
            return Touched::Kept;
        }
        let mut touched = Touched::Kept;
        if self.robots.len() >= self.capacity {
            let least = |only_unnamed: bool| {
                self.robots
                    .iter()
                    .filter(|(name, _)| !only_unnamed || !named(name))
                    .min_by_key(|(_, (last, _))| *last)
                    .map(|(name, _)| name.clone())
            };
            // A robot the sim names may take the place of any other; a stranger only that
            // of another stranger.
            let victim = least(true).or_else(|| if named(robot) { least(false) } else { None });
            let Some(victim) = victim else {
                return Touched::Refused;
            };
            self.robots.remove(&victim);
            touched = Touched::Evicted(victim);
        }
        self.robots.insert(robot.to_owned(), (self.clock, make()));
        touched
    }

    pub(crate) fn get_mut(&mut self, robot: &str) -> Option<&mut T> {
        self.robots.get_mut(robot).map(|(_, state)| state)
    }

    pub(crate) fn remove(&mut self, robot: &str) -> Option<T> {
        self.robots.remove(robot).map(|(_, state)| state)
    }

    pub(crate) fn contains(&self, robot: &str) -> bool {
        self.robots.contains_key(robot)
    }

    pub(crate) fn len(&self) -> usize {
        self.robots.len()
    }

    pub(crate) fn names(&self) -> impl Iterator<Item = &str> {
        self.robots.keys().map(String::as_str)
    }

    pub(crate) fn iter_mut(&mut self) -> impl Iterator<Item = (&str, &mut T)> {
        self.robots
            .iter_mut()
            .map(|(name, (_, state))| (name.as_str(), state))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn nobody(_: &str) -> bool {
        false
    }

    #[test]
    fn a_full_roster_evicts_the_least_recent_robot() {
        let mut roster = Roster::new(2);
        assert_eq!(roster.touch("a", nobody, || 1), Touched::Kept);
        assert_eq!(roster.touch("b", nobody, || 2), Touched::Kept);
        assert_eq!(
            roster.touch("a", nobody, || 9),
            Touched::Kept,
            "a is fresh again"
        );
        assert_eq!(roster.get_mut("a"), Some(&mut 1), "known: not made again");
        assert_eq!(
            roster.touch("c", nobody, || 3),
            Touched::Evicted("b".into())
        );
        assert_eq!(roster.len(), 2);
        assert!(roster.contains("a") && roster.contains("c") && !roster.contains("b"));
    }

    #[test]
    fn strangers_never_evict_the_robots_the_sim_names() {
        let sim = |name: &str| name == "robot";
        let mut roster = Roster::new(3);
        roster.touch("robot", sim, || ());
        for i in 0..1000 {
            let touched = roster.touch(&format!("ghost-{i}"), sim, || ());
            assert_ne!(touched, Touched::Evicted("robot".into()), "at {i}");
        }
        assert_eq!(roster.len(), 3);
        assert!(roster.contains("robot"));
        assert!(roster.contains("ghost-999") && roster.contains("ghost-998"));
    }

    #[test]
    fn a_roster_full_of_named_robots_refuses_strangers_but_not_named_ones() {
        let sim = |name: &str| name.starts_with("sim-");
        let mut roster = Roster::new(2);
        roster.touch("sim-1", sim, || ());
        roster.touch("sim-2", sim, || ());
        assert_eq!(roster.touch("ghost", sim, || ()), Touched::Refused);
        assert!(!roster.contains("ghost"));
        assert_eq!(
            roster.touch("sim-3", sim, || ()),
            Touched::Evicted("sim-1".into())
        );
        assert_eq!(roster.remove("sim-2"), Some(()));
        assert_eq!(roster.touch("ghost", sim, || ()), Touched::Kept);
    }
}
