//! How a long run says how far it is: a callback the runner calls after each unit of
//! work. The runners only count; the `roam` binary decides what a person sees (a bar
//! on a terminal, a line per stage in a log, nothing with `--quiet`), so this crate
//! writes nothing to stderr and never depends on a terminal library.

/// One report: `done` of `total` units of `stage` are finished.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Done<'a> {
    /// What is running, e.g. `es2` or `plans`: a new stage starts a new count (and a
    /// new bar), so a runner with parts of different cost can say so.
    pub stage: &'a str,
    /// What is counted, plural: `runs`, `plans`, `days`, `seconds`.
    pub unit: &'static str,
    pub done: u64,
    pub total: u64,
}

impl<'a> Done<'a> {
    /// `done` of `total` `unit` of `stage`, from the `usize` counts the runners keep.
    pub fn of(stage: &'a str, unit: &'static str, done: usize, total: usize) -> Done<'a> {
        Done {
            stage,
            unit,
            done: done as u64,
            total: total as u64,
        }
    }
}

/// What a runner calls after each unit of work; `Sync` because the runs of a batch
/// finish on several threads ([`crate::parallel::run_in_order`]).
pub type Progress<'a> = &'a (dyn Fn(Done<'_>) + Sync);

/// A [`Progress`] that ignores every report, for tests and callers that show nothing.
pub fn silent(_: Done<'_>) {}
