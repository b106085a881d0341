//! A request admitted in its client's fair share, or refused at once.

use std::time::Instant;

use super::client::ClientId;
use super::rounds::{Inner, Job};
use super::state::PlanQueue;
use super::ticket::Ticket;

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

impl PlanQueue {
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

#[cfg(test)]
mod tests {
    use std::time::Duration;

    use tokio_util::sync::CancellationToken;

    use super::*;
    use crate::queue::rate::PRIOR_SECONDS_PER_UNIT;
    use crate::queue::state::QueueConfig;
    use crate::queue::ticket::Turn;

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
}
