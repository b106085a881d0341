//! The instance's plan queue: each client gets its share, a burst is served in order, or
//! refused at once.
//!
//! An instance plans `max_concurrent_plans` requests at a time; the next ones wait in a
//! bounded queue of `max_queued_plans`. **Each client has a fair share** (start-time fair
//! queuing, one round per request): a request's round is the later of the round being
//! served and the round after its client's previous request, and the queue serves
//! rounds in order (arrival order within a round and within a client). A client that
//! queued 10,000 requests holds rounds far ahead; a newcomer's request is served next,
//! after the requests of the round being served. When the queue is full, a request whose
//! round comes before the last queued one takes that one's place (the displaced request
//! is refused `busy`), so a flood fills the queue only with itself. A client is who the
//! request says it is ([`ClientId`]: the query's `client` parameter; roam's own
//! clients send their Zenoh session's id): a share against a runaway client, not
//! against a stranger who invents names.
//!
//! A request is admitted when its *expected
//! wait* plus its *expected planning time* fits its `deadline_s` (which counts from its
//! arrival: the wait is part of it); otherwise it is refused `busy` at once, with the
//! expected wait in the error (`expected_wait_s`) so that a client can choose another
//! instance or retry. A request that finds a slot free is admitted whatever its
//! planning time: the GA is anytime, and its deadline cuts it as it always did.
//!
//! **Expected times, from the instance's measured rate.** A plan's work is measured in
//! *units*: the limits' cost (population × generations × the longest path the budget
//! allows, [`crate::limits`]) plus [`OVERHEAD_UNITS`] for what every plan does besides
//! the GA (locating, the fastest path, seeds, driving). Every plan that ends updates
//! the instance's seconds per unit (an exponential average, [`Rate`]) from its wall
//! time and the units it did (a plan cut at its deadline did the share of its
//! generations it ran), so the rate includes whatever else shares the cores. A plan is
//! expected to take `units × rate`, at most its deadline and `max_plan_seconds`. The
//! expected wait of a newcomer: each slot is free when its plan's expected time has
//! passed, and the queued plans take the earliest free slot in order.
//!
//! **Memory stays bounded**: the queue holds at most `max_queued_plans` requests (each
//! at most [`crate::service::MAX_REQUEST_BYTES`] on the wire), and a request is refused
//! before it is queued. A queued request can be cancelled by its requester like a
//! running one ([`crate::inflight`]); it then leaves the queue at once.

use std::collections::{HashMap, HashSet, VecDeque};
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};

use tokio_util::sync::CancellationToken;

/// The most requests an instance may queue.
pub const MAX_QUEUED_PLANS: usize = 10_000;
/// The units of what every plan does besides the GA's generations.
pub const OVERHEAD_UNITS: f64 = 2.0e6;
/// The seconds per unit one plan alone takes, as an instance assumes before its first
/// plan ends: 10 ns, about what the paper's workload measures on a 2-core machine
/// (Model I, 0.2 m cells). Its plans share the cores, so the instance starts from this
/// times `max_concurrent_plans`.
pub const PRIOR_SECONDS_PER_UNIT: f64 = 1.0e-8;
/// The weight of the newest measurement in the rate's average.
pub const RATE_WEIGHT: f64 = 0.3;
/// The longest client name kept; a longer one is cut there.
pub const MAX_CLIENT_ID_BYTES: usize = 64;

/// Who a request is from, for its fair share: the name the client gives (clipped to
/// [`MAX_CLIENT_ID_BYTES`]), or one shared name for every client that gives none.
#[derive(Debug, Clone, PartialEq, Eq, Hash)]
pub struct ClientId(Arc<str>);

impl ClientId {
    /// The share of the requests that name no client.
    pub fn anonymous() -> ClientId {
        ClientId(Arc::from(""))
    }

    /// The client named `name` (empty: [`ClientId::anonymous`]).
    pub fn named(name: &str) -> ClientId {
        let mut end = name.len().min(MAX_CLIENT_ID_BYTES);
        while !name.is_char_boundary(end) {
            end -= 1;
        }
        ClientId(Arc::from(&name[..end]))
    }

    pub fn as_str(&self) -> &str {
        &self.0
    }
}

/// The queue's settings (see [`crate::PlannerConfig`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct QueueConfig {
    pub max_concurrent_plans: usize,
    pub max_queued_plans: usize,
}

/// Seconds per unit of plan work, measured (see the module doc).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Rate {
    pub seconds_per_unit: f64,
    pub samples: u64,
}

impl Default for Rate {
    fn default() -> Self {
        Rate {
            seconds_per_unit: PRIOR_SECONDS_PER_UNIT,
            samples: 0,
        }
    }
}

impl Rate {
    /// Takes a plan that did `units` of work in `seconds` of wall time.
    pub fn measure(&mut self, units: f64, seconds: f64) {
        if !(units.is_finite() && units > 0.0 && seconds.is_finite() && seconds >= 0.0) {
            return;
        }
        let measured = seconds / units;
        self.seconds_per_unit = if self.samples == 0 {
            measured
        } else {
            RATE_WEIGHT * measured + (1.0 - RATE_WEIGHT) * self.seconds_per_unit
        };
        self.samples += 1;
    }
}

/// The units of a plan whose GA costs `cost` ([`crate::limits::PlanSize::cost`]; 0
/// for a plan without generations).
pub fn units(cost: u64) -> f64 {
    OVERHEAD_UNITS + cost as f64
}

#[derive(Debug, Clone)]
struct Job {
    id: u64,
    client: ClientId,
    /// Its fair-share round: the queue serves rounds in order.
    round: u64,
    /// Arrival order, within a round.
    seq: u64,
    /// Expected seconds of planning.
    expected_s: f64,
    /// When it started planning (running) or was admitted (waiting).
    since: Instant,
}

impl Job {
    fn order(&self) -> (u64, u64) {
        (self.round, self.seq)
    }
}

/// A client's place in the rounds.
#[derive(Debug, Clone, Copy, Default)]
struct Share {
    /// The round its next request takes at the earliest.
    next_round: u64,
    /// Its requests running or waiting (the entry goes at 0).
    jobs: usize,
}

#[derive(Debug, Default)]
struct Inner {
    running: Vec<Job>,
    /// In `(round, seq)` order.
    waiting: VecDeque<Job>,
    /// The round of the request that started last.
    round: u64,
    clients: HashMap<ClientId, Share>,
    /// Requests that lost their place to a request of an earlier round.
    displaced: HashSet<u64>,
    rate: Rate,
    next_id: u64,
}

impl Inner {
    /// Forgets a request (running or waiting) and its client's share when it was the
    /// client's last.
    fn remove(&mut self, id: u64) {
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
    fn insert(&mut self, mut job: Job) {
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

/// Why a request was not admitted.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Refusal {
    /// The queue holds `max_queued_plans` already.
    Full { queued: usize, expected_wait_s: f64 },
    /// The expected wait plus the expected planning time is past the deadline.
    Late {
        expected_wait_s: f64,
        expected_plan_s: f64,
        deadline_s: f64,
        queued: usize,
    },
}

impl Refusal {
    pub fn expected_wait_s(&self) -> f64 {
        match *self {
            Refusal::Full {
                expected_wait_s, ..
            }
            | Refusal::Late {
                expected_wait_s, ..
            } => expected_wait_s,
        }
    }
}

/// A request admitted to the queue; it leaves the queue when dropped (cancelled,
/// refused later, or done).
#[derive(Debug)]
pub struct Ticket<'a> {
    queue: &'a PlanQueue,
    id: u64,
    /// When it arrived: its deadline counts from here.
    pub arrived: Instant,
    pub expected_wait_s: f64,
    pub expected_plan_s: f64,
    /// Whether it had to queue (no slot was free for it on arrival).
    pub queued: bool,
    units: f64,
    started: Option<Instant>,
}

/// What [`Ticket::wait_turn`] ended with.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Turn {
    /// A slot is this request's: plan now.
    Plan,
    /// The requester cancelled (or the instance is stopping) while it was queued.
    Cancelled,
    /// The queue was full and a request of an earlier round took this one's place.
    Displaced,
}

/// The queue of one instance.
#[derive(Debug)]
pub struct PlanQueue {
    config: QueueConfig,
    inner: Mutex<Inner>,
    changed: tokio::sync::Notify,
}

impl PlanQueue {
    pub fn new(config: QueueConfig) -> Self {
        let shared = config.max_concurrent_plans.max(1) as f64;
        PlanQueue {
            config,
            inner: Mutex::new(Inner {
                rate: Rate {
                    seconds_per_unit: PRIOR_SECONDS_PER_UNIT * shared,
                    samples: 0,
                },
                ..Inner::default()
            }),
            changed: tokio::sync::Notify::new(),
        }
    }

    fn lock(&self) -> std::sync::MutexGuard<'_, Inner> {
        roam_runtime::lock(&self.inner)
    }

    pub fn config(&self) -> QueueConfig {
        self.config
    }

    /// The measured rate.
    pub fn rate(&self) -> Rate {
        self.lock().rate
    }

    /// Plans running and plans queued.
    pub fn load(&self) -> (usize, usize) {
        let inner = self.lock();
        (inner.running.len(), inner.waiting.len())
    }

    /// Seconds a plan of `units` is expected to take, at most `cap_s`.
    pub fn expected_plan_s(&self, units: f64, cap_s: f64) -> f64 {
        (units * self.lock().rate.seconds_per_unit).min(cap_s)
    }

    /// The expected wait at `now` of a request behind the first `ahead` queued ones
    /// (see the module doc).
    fn expected_wait(&self, inner: &Inner, now: Instant, ahead: usize) -> f64 {
        let mut free_at: Vec<f64> = inner
            .running
            .iter()
            .map(|j| (j.expected_s - now.saturating_duration_since(j.since).as_secs_f64()).max(0.0))
            .collect();
        free_at.resize(free_at.len().max(self.config.max_concurrent_plans), 0.0);
        let earliest = |free_at: &[f64]| {
            (0..free_at.len())
                .min_by(|&a, &b| free_at[a].total_cmp(&free_at[b]))
                .unwrap_or(0)
        };
        for job in inner.waiting.iter().take(ahead) {
            let i = earliest(&free_at);
            free_at[i] += job.expected_s;
        }
        free_at.get(earliest(&free_at)).copied().unwrap_or(0.0)
    }

    /// Admits the request that arrived `seq`-th at `now` from `client`, of `units` of
    /// work ([`units`]), with `deadline_s` from `now` and its planning at most
    /// `max_plan_s` (the CPU budget's `max_plan_seconds`); or refuses it. Its place is
    /// its client's fair share (see the module doc).
    pub fn admit(
        &self,
        seq: u64,
        client: &ClientId,
        units: f64,
        deadline_s: f64,
        max_plan_s: f64,
        now: Instant,
    ) -> Result<Ticket<'_>, Refusal> {
        let mut inner = self.lock();
        let share = inner.clients.get(client).copied().unwrap_or_default();
        // The round the client's newest request takes; this one's place is the round
        // of the client's first request that arrived after it, if one is queued.
        let round = share.next_round.max(inner.round);
        let place = inner
            .waiting
            .iter()
            .filter(|j| j.client == *client && j.seq > seq)
            .map(|j| j.round)
            .min()
            .unwrap_or(round);
        let order = (place, seq);
        let ahead = inner.waiting.partition_point(|j| j.order() < order);
        let wait = self.expected_wait(&inner, now, ahead);
        let plan = (units * inner.rate.seconds_per_unit).min(max_plan_s);
        let queued = inner.waiting.len();
        let slot_free = inner.running.len() < self.config.max_concurrent_plans && ahead == 0;
        if !slot_free {
            if queued >= self.config.max_queued_plans {
                let last_is_later = inner.waiting.back().is_some_and(|j| j.order() > order);
                if !last_is_later {
                    return Err(Refusal::Full {
                        queued,
                        expected_wait_s: wait,
                    });
                }
            }
            if wait + plan > deadline_s {
                return Err(Refusal::Late {
                    expected_wait_s: wait,
                    expected_plan_s: plan,
                    deadline_s,
                    queued,
                });
            }
            if queued >= self.config.max_queued_plans {
                if let Some(last) = inner.waiting.back().map(|j| j.id) {
                    inner.remove(last);
                    inner.displaced.insert(last);
                    self.changed.notify_waiters();
                }
            }
        }
        let id = inner.next_id;
        inner.next_id += 1;
        let entry = inner.clients.entry(client.clone()).or_default();
        entry.next_round = round + 1;
        entry.jobs += 1;
        inner.insert(Job {
            id,
            client: client.clone(),
            round,
            seq,
            expected_s: plan.min(deadline_s),
            since: now,
        });
        Ok(Ticket {
            queue: self,
            id,
            arrived: now,
            expected_wait_s: if slot_free { 0.0 } else { wait },
            expected_plan_s: plan,
            queued: !slot_free,
            units,
            started: None,
        })
    }
}

impl Ticket<'_> {
    /// Moves this request from the queue to a slot if it is first in line and a slot
    /// is free.
    fn try_start(&mut self, now: Instant) -> Option<Turn> {
        let queue = self.queue;
        let mut inner = queue.lock();
        if inner.displaced.remove(&self.id) {
            return Some(Turn::Displaced);
        }
        let first = inner.waiting.front().is_some_and(|j| j.id == self.id);
        if !first || inner.running.len() >= queue.config.max_concurrent_plans {
            return None;
        }
        if let Some(mut job) = inner.waiting.pop_front() {
            job.since = now;
            inner.round = inner.round.max(job.round);
            inner.running.push(job);
            self.started = Some(now);
        }
        Some(Turn::Plan)
    }

    /// Waits until a slot is this request's, in its client's fair turn, or until
    /// `cancel`, or until it is displaced.
    pub async fn wait_turn(&mut self, cancel: &CancellationToken) -> Turn {
        loop {
            let changed = self.queue.changed.notified();
            tokio::pin!(changed);
            // Registered before the check, so no wake-up between them is lost.
            changed.as_mut().enable();
            if let Some(turn) = self.try_start(Instant::now()) {
                return turn;
            }
            tokio::select! {
                _ = &mut changed => {}
                _ = cancel.cancelled() => {
                    return Turn::Cancelled;
                }
            }
        }
    }

    /// When it left the queue for a slot.
    pub fn started(&self) -> Option<Instant> {
        self.started
    }

    /// Ends a plan that did `share` (0..=1) of its generations: the rate learns from
    /// its wall time over the units it did ([`OVERHEAD_UNITS`] and that share of the
    /// rest). Dropping the ticket frees the slot.
    pub fn finish(self, share: f64, now: Instant) {
        if let Some(started) = self.started {
            let seconds = now.saturating_duration_since(started).as_secs_f64();
            let work = (self.units - OVERHEAD_UNITS).max(0.0);
            let done = OVERHEAD_UNITS + work * share.clamp(0.0, 1.0);
            self.queue.lock().rate.measure(done, seconds);
        }
    }

    /// Seconds of its deadline left at `now`.
    pub fn remaining_s(&self, deadline_s: f64, now: Instant) -> f64 {
        deadline_s - now.saturating_duration_since(self.arrived).as_secs_f64()
    }

    /// How long it waited in the queue.
    pub fn waited(&self) -> Duration {
        self.started.map_or(Duration::ZERO, |s| {
            s.saturating_duration_since(self.arrived)
        })
    }
}

impl Drop for Ticket<'_> {
    fn drop(&mut self) {
        let mut inner = self.queue.lock();
        inner.remove(self.id);
        drop(inner);
        self.queue.changed.notify_waiters();
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The client of the tests that have one.
    fn one() -> ClientId {
        ClientId::named("one")
    }

    fn queue(concurrent: usize, queued: usize) -> PlanQueue {
        PlanQueue::new(QueueConfig {
            max_concurrent_plans: concurrent,
            max_queued_plans: queued,
        })
    }

    /// 1 s of work at the prior rate of a queue of one slot (`queue(1, ..)`); tests of
    /// two slots divide by two.
    const ONE_S: f64 = 1.0 / PRIOR_SECONDS_PER_UNIT;

    #[test]
    fn the_expected_wait_fills_the_slots_in_order() {
        let q = queue(2, 10);
        // Two slots share the cores: the prior rate is twice one plan's.
        const ONE_S: f64 = super::tests::ONE_S / 2.0;
        let now = Instant::now();
        let mut a = q.admit(1, &one(), 2.0 * ONE_S, 30.0, 30.0, now).expect("a");
        assert_eq!(a.try_start(now), Some(Turn::Plan));
        let mut b = q.admit(2, &one(), ONE_S, 30.0, 30.0, now).expect("b");
        assert_eq!(b.try_start(now), Some(Turn::Plan));
        // Both slots busy: free in 1 s (b) and 2 s (a).
        let c = q.admit(3, &one(), 3.0 * ONE_S, 30.0, 30.0, now).expect("c");
        assert!((c.expected_wait_s - 1.0).abs() < 1e-9);
        // c takes b's slot at 1 s and ends at 4 s; d gets a's at 2 s.
        let d = q.admit(4, &one(), ONE_S, 30.0, 30.0, now).expect("d");
        assert!(
            (d.expected_wait_s - 2.0).abs() < 1e-9,
            "{}",
            d.expected_wait_s
        );
        // 1 s later the running plans have 0 and 1 s left.
        let later = now + Duration::from_secs(1);
        let e = q.admit(5, &one(), ONE_S, 30.0, 30.0, later).expect("e");
        // Slots free at 0 and 1; c takes 0 → 3, d takes 1 → 2: e waits 2 s.
        assert!(
            (e.expected_wait_s - 2.0).abs() < 1e-9,
            "{}",
            e.expected_wait_s
        );
        drop((a, b, c, d, e));
        assert_eq!(q.load(), (0, 0));
    }

    #[test]
    fn a_request_that_cannot_make_its_deadline_is_refused_with_the_wait() {
        let q = queue(1, 10);
        let now = Instant::now();
        let mut a = q
            .admit(6, &one(), 10.0 * ONE_S, 30.0, 30.0, now)
            .expect("a");
        assert_eq!(a.try_start(now), Some(Turn::Plan));
        // 10 s wait + 1 s plan > 5 s.
        match q.admit(7, &one(), ONE_S, 5.0, 30.0, now) {
            Err(Refusal::Late {
                expected_wait_s,
                expected_plan_s,
                deadline_s,
                queued,
            }) => {
                assert!((expected_wait_s - 10.0).abs() < 1e-9);
                assert!((expected_plan_s - 1.0).abs() < 1e-9);
                assert_eq!((deadline_s, queued), (5.0, 0));
            }
            other => panic!("{other:?}"),
        }
        // 10 s + 1 s fits 30 s; a free slot admits anything.
        assert!(q.admit(8, &one(), ONE_S, 30.0, 30.0, now).is_ok());
        drop(a);
        let q = queue(1, 10);
        assert!(q.admit(9, &one(), 100.0 * ONE_S, 1.0, 30.0, now).is_ok());
    }

    #[test]
    fn the_queue_is_bounded() {
        let q = queue(1, 2);
        let now = Instant::now();
        let mut a = q.admit(10, &one(), ONE_S, 60.0, 60.0, now).expect("a");
        assert_eq!(a.try_start(now), Some(Turn::Plan));
        let _b = q.admit(11, &one(), ONE_S, 60.0, 60.0, now).expect("b");
        let _c = q.admit(12, &one(), ONE_S, 60.0, 60.0, now).expect("c");
        match q.admit(13, &one(), ONE_S, 60.0, 60.0, now) {
            Err(Refusal::Full {
                queued,
                expected_wait_s,
            }) => {
                assert_eq!(queued, 2);
                assert!((expected_wait_s - 3.0).abs() < 1e-9);
            }
            other => panic!("{other:?}"),
        };
    }

    #[tokio::test]
    async fn turns_come_in_arrival_order_and_a_cancel_leaves_the_queue() {
        let q = queue(1, 10);
        let now = Instant::now();
        let never = CancellationToken::new();
        let mut a = q.admit(14, &one(), ONE_S, 60.0, 60.0, now).expect("a");
        assert_eq!(a.wait_turn(&never).await, Turn::Plan);
        let mut b = q.admit(15, &one(), ONE_S, 60.0, 60.0, now).expect("b");
        let mut c = q.admit(16, &one(), ONE_S, 60.0, 60.0, now).expect("c");
        let cancel_b = CancellationToken::new();
        cancel_b.cancel();
        assert_eq!(b.wait_turn(&cancel_b).await, Turn::Cancelled);
        drop(b);
        assert_eq!(q.load(), (1, 1));
        // c waits for a, then plans.
        let never = CancellationToken::new();
        let early = tokio::time::timeout(Duration::from_millis(50), c.wait_turn(&never)).await;
        assert!(early.is_err(), "c's turn comes after a's");
        assert!(c.started().is_none());
        a.finish(1.0, Instant::now());
        assert_eq!(c.wait_turn(&never).await, Turn::Plan);
        assert!(c.started().is_some());
        assert_eq!(q.rate().samples, 1);
    }

    #[test]
    fn the_queue_serves_arrival_order_whatever_order_requests_reach_it() {
        let q = queue(1, 10);
        let now = Instant::now();
        let mut a = q.admit(0, &one(), ONE_S, 60.0, 60.0, now).expect("a");
        assert_eq!(a.try_start(now), Some(Turn::Plan));
        let mut late = q.admit(9, &one(), ONE_S, 60.0, 60.0, now).expect("9th");
        let mut early = q
            .admit(5, &one(), 2.0 * ONE_S, 60.0, 60.0, now)
            .expect("5th");
        // The 5th goes first: its wait is a's 1 s, the 9th's is 1 + 2.
        assert!((early.expected_wait_s - 1.0).abs() < 1e-9);
        drop(a);
        assert_eq!(late.try_start(now), None);
        assert_eq!(early.try_start(now), Some(Turn::Plan));
        drop(early);
        assert_eq!(late.try_start(now), Some(Turn::Plan));
    }

    #[test]
    fn a_newcomer_is_served_before_a_flooding_client_s_backlog() {
        let q = queue(1, 100);
        let now = Instant::now();
        let flood = ClientId::named("flood");
        let mut running = q.admit(0, &flood, ONE_S, 1e6, 1e6, now).expect("first");
        assert_eq!(running.try_start(now), Some(Turn::Plan));
        let backlog: Vec<_> = (1..=50)
            .map(|i| q.admit(i, &flood, ONE_S, 1e6, 1e6, now).expect("backlog"))
            .collect();
        // Another client's request waits only for the plan running, not the backlog.
        let mut other = q
            .admit(51, &ClientId::named("other"), ONE_S, 3.0, 1e6, now)
            .expect("a fair share");
        assert!(
            (other.expected_wait_s - 1.0).abs() < 1e-9,
            "{}",
            other.expected_wait_s
        );
        drop(running);
        assert_eq!(other.try_start(now), Some(Turn::Plan));
        // A client with one request at a time is always next. With two queued, its
        // second shares round 1 with the flood's next, which arrived first.
        drop(other);
        let mut third = q
            .admit(52, &ClientId::named("other"), ONE_S, 1e6, 1e6, now)
            .expect("third");
        let mut fourth = q
            .admit(53, &ClientId::named("other"), ONE_S, 1e6, 1e6, now)
            .expect("fourth");
        assert_eq!(third.try_start(now), Some(Turn::Plan));
        drop(third);
        let mut backlog = backlog.into_iter();
        let mut next = backlog.next().expect("the flood's next");
        assert_eq!(
            fourth.try_start(now),
            None,
            "round 1: the flood's arrived first"
        );
        assert_eq!(next.try_start(now), Some(Turn::Plan));
        drop(next);
        assert_eq!(fourth.try_start(now), Some(Turn::Plan));
        let again = fourth;
        drop((again, backlog));
        assert_eq!(q.load(), (0, 0));
        assert!(
            q.lock().clients.is_empty(),
            "no client is kept after its last request"
        );
    }

    #[test]
    fn a_full_queue_gives_the_flood_s_last_place_to_another_client() {
        let q = queue(1, 3);
        let now = Instant::now();
        let flood = ClientId::named("flood");
        let mut running = q.admit(0, &flood, ONE_S, 1e6, 1e6, now).expect("first");
        assert_eq!(running.try_start(now), Some(Turn::Plan));
        let mut backlog: Vec<_> = (1..=3)
            .map(|i| q.admit(i, &flood, ONE_S, 1e6, 1e6, now).expect("backlog"))
            .collect();
        assert!(matches!(
            q.admit(4, &flood, ONE_S, 1e6, 1e6, now),
            Err(Refusal::Full { .. })
        ));
        let mut other = q
            .admit(5, &ClientId::named("other"), ONE_S, 1e6, 1e6, now)
            .expect("a place");
        assert_eq!(backlog[2].try_start(now), Some(Turn::Displaced));
        assert_eq!(q.load(), (1, 3));
        drop(running);
        assert_eq!(other.try_start(now), Some(Turn::Plan));
        drop(backlog.remove(2));
        assert_eq!(q.load(), (1, 2));
    }

    #[test]
    fn client_names_are_clipped() {
        let long = "é".repeat(100);
        assert!(ClientId::named(&long).as_str().len() <= MAX_CLIENT_ID_BYTES);
        assert_eq!(ClientId::named(""), ClientId::anonymous());
    }

    #[test]
    fn the_rate_learns_from_what_plans_took() {
        let mut rate = Rate::default();
        rate.measure(1e8, 2.0);
        assert!((rate.seconds_per_unit - 2e-8).abs() < 1e-20);
        rate.measure(1e8, 1.0);
        assert!((rate.seconds_per_unit - (0.3 * 1e-8 + 0.7 * 2e-8)).abs() < 1e-20);
        rate.measure(0.0, 1.0);
        rate.measure(1e8, f64::NAN);
        assert_eq!(rate.samples, 2);
    }
}
