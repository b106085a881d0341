//! The requests running and waiting, in their clients' fair-share rounds.

use std::collections::{HashMap, HashSet, VecDeque};
use std::time::Instant;

use super::client::ClientId;
use super::rate::Rate;

#[derive(Debug, Clone)]
pub(super) struct Job {
    pub(super) id: u64,
    pub(super) client: ClientId,
    /// Its fair-share round: the queue serves rounds in order.
    pub(super) round: u64,
    /// Arrival order, within a round.
    pub(super) seq: u64,
    /// Expected seconds of planning.
    pub(super) expected_s: f64,
    /// When it started planning (running) or was admitted (waiting).
    pub(super) since: Instant,
}

impl Job {
    pub(super) fn order(&self) -> (u64, u64) {
        (self.round, self.seq)
    }
}

/// A client's place in the rounds.
#[derive(Debug, Clone, Copy, Default)]
pub(super) struct Share {
    /// The round its next request takes at the earliest.
    pub(super) next_round: u64,
    /// Its requests running or waiting (the entry goes at 0).
    pub(super) jobs: usize,
}

#[derive(Debug, Default)]
pub(super) struct Inner {
    pub(super) running: Vec<Job>,
    /// In `(round, seq)` order.
    pub(super) waiting: VecDeque<Job>,
    /// The round of the request that started last.
    pub(super) round: u64,
    pub(super) clients: HashMap<ClientId, Share>,
    /// Requests that lost their place to a request of an earlier round.
    pub(super) displaced: HashSet<u64>,
    pub(super) rate: Rate,
    pub(super) next_id: u64,
}

impl Inner {
    /// Forgets a request (running or waiting) and its client's share when it was the
    /// client's last.
    pub(super) fn remove(&mut self, id: u64) {
        let gone = if let Some(at) = self.running.iter().position(|j| j.id == id) {
            Some(self.running.swap_remove(at))
        } else if let Some(at) = self.waiting.iter().position(|j| j.id == id) {
            self.waiting.remove(at)
        } else {
            None
        };
        self.displaced.remove(&id);
        if let Some(job) = gone {
            if let Some(share) = self.clients.get_mut(&job.client) {
                share.jobs = share.jobs.saturating_sub(1);
                if share.jobs == 0 {
                    self.clients.remove(&job.client);
                }
            }
        }
    }

    /// Queues `job` in its place. A request that reached the queue after a later one
    /// of the same client (requests are checked concurrently) takes that one's round,
    /// and the client's later requests move one round on.
    pub(super) fn insert(&mut self, mut job: Job) {
        let later_of_client = self
            .waiting
            .iter()
            .any(|j| j.client == job.client && j.seq > job.seq);
        if later_of_client {
            let mut rounds: Vec<u64> = self
                .waiting
                .iter()
                .filter(|j| j.client == job.client)
                .map(|j| j.round)
                .chain([job.round])
                .collect();
            rounds.sort_unstable();
            let client = job.client.clone();
            let mut mine: Vec<&mut Job> = self
                .waiting
                .iter_mut()
                .filter(|j| j.client == client)
                .chain([&mut job])
                .collect();
            mine.sort_by_key(|j| j.seq);
            for (j, round) in mine.into_iter().zip(rounds) {
                j.round = round;
            }
            self.waiting.push_back(job);
            self.waiting.make_contiguous().sort_by_key(Job::order);
        } else {
            let at = self.waiting.partition_point(|j| j.order() < job.order());
            self.waiting.insert(at, job);
        }
    }
}
