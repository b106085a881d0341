//! Zenoh's own thread pools, sized for a process that holds many sessions.
//!
//! Zenoh runs every session of a process on the same few process-wide tokio runtimes
//! (`zenoh_runtime::ZRuntime`); the receive runtime has 2 worker threads by default. A
//! router routes a message inside the receive task of the link it came in on, and when
//! the peer it goes to has no room (a 48 MB query still being written), that task
//! blocks its worker until there is. In a process that holds the router *and* the
//! services (`roam stack`, `roam demo`, the test harness), the service's own receive
//! task needs a worker of that same runtime to drain its link: with both workers
//! blocked, nothing drains, and after Zenoh's `wait_before_close` (5 s) the router
//! closes the service's transport ("Unable to push non droppable network message …
//! Closing transport!"), dropping every query in flight. Measured on `roam stack`:
//! four 48 MB queries to `mapper/status` from one client got 1 answer of 4 and closed
//! the mapper's transport with the default 2 workers, 4 of 4 answers in under 1 s with 8.
//!
//! So roam gives the receive runtime [`RX_WORKER_THREADS`] workers, more than the
//! sessions of the in-process stack, unless the user set `ZENOH_RUNTIME` themselves.
//! Idle workers cost a thread stack each. A router facing strangers on the network is
//! best run as its own process (`roam router`, deploy/README.md), where no service can
//! be starved by it.

/// The environment variable Zenoh reads its runtimes' sizes from (RON).
pub const ZENOH_RUNTIME_ENV: &str = "ZENOH_RUNTIME";
/// Worker threads of Zenoh's receive runtime that roam asks for.
pub const RX_WORKER_THREADS: usize = 16;

/// The `ZENOH_RUNTIME` roam sets when the user has not.
pub fn default_setting() -> String {
    format!("(rx: (worker_threads: {RX_WORKER_THREADS}))")
}

/// What [`provision`] found.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Provision {
    /// `ZENOH_RUNTIME` was unset: roam's [`default_setting`] now applies.
    Set(String),
    /// The user's `ZENOH_RUNTIME` stays.
    Kept(String),
}

/// Sets `ZENOH_RUNTIME` to [`default_setting`] unless it is set already. It changes the
/// process's environment, so call it first thing in `main`, before any other thread
/// starts and before anything touches Zenoh (which reads the variable once).
pub fn provision() -> Provision {
    match std::env::var(ZENOH_RUNTIME_ENV) {
        Ok(value) if !value.trim().is_empty() => Provision::Kept(value),
        _ => {
            let value = default_setting();
            std::env::set_var(ZENOH_RUNTIME_ENV, &value);
            Provision::Set(value)
        }
    }
}
