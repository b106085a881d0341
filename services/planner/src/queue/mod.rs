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

mod admit;
mod client;
mod rate;
mod rounds;
mod state;
mod ticket;

pub use admit::Refusal;
pub use client::{ClientId, MAX_CLIENT_ID_BYTES};
pub use rate::{units, Rate, OVERHEAD_UNITS, PRIOR_SECONDS_PER_UNIT, RATE_WEIGHT};
pub use state::{PlanQueue, QueueConfig};
pub use ticket::{Ticket, Turn};

/// The most requests an instance may queue.
pub const MAX_QUEUED_PLANS: usize = 10_000;
