//! How an experiment's runs are run: how many, from which seed (each run's own seed
//! derived from its place, never from the order runs happen in), on how many threads
//! (the results put back in run order).

use crate::parallel::run_in_order;
use crate::progress::Progress;
use roam_controller::params::ApfParams;

use super::error::ApfError;

/// How many runs, from which seed, on how many threads, reporting progress how.
#[derive(Clone, Copy)]
pub struct RunOptions<'a> {
    /// Runs per configuration (ES1: per scheme; ES2: per scheme and z_is; ES3: per
    /// scheme and mission).
    pub runs: usize,
    /// The base seed every run's seed is derived from.
    pub seed: u64,
    /// Worker threads (at least one is used).
    pub threads: usize,
    /// The controller's parameters; each experiment sets the scheme and z_is (and what
    /// else it says) on top.
    pub params: &'a ApfParams,
    /// Called after every finished run: the experiment (`es1`, `es2`, `es3`) as the
    /// stage, runs done and runs in total.
    pub progress: Progress<'a>,
}

impl std::fmt::Debug for RunOptions<'_> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("RunOptions")
            .field("runs", &self.runs)
            .field("seed", &self.seed)
            .field("threads", &self.threads)
            .field("params", self.params)
            .finish_non_exhaustive()
    }
}

/// The most runs one configuration may have.
pub const MAX_RUNS: usize = 100_000;
/// The most ES3 missions.
pub const MAX_MISSIONS: usize = 10_000;

impl RunOptions<'_> {
    pub(crate) fn check(&self) -> Result<(), ApfError> {
        if !(1..=MAX_RUNS).contains(&self.runs) {
            return Err(ApfError::BadOption {
                name: "runs",
                value: self.runs,
                expected: "use 1 to 100000 runs",
            });
        }
        self.params.check()?;
        Ok(())
    }
}

/// The seed of one run: a hash of the base seed and the run's place (experiment,
/// mission, run), so a run's noise does not depend on which other runs exist. The scheme
/// is left out on purpose: every scheme meets the same noise (common random numbers,
/// module doc).
pub fn run_seed(base: u64, experiment: &str, mission: usize, run: usize) -> u64 {
    roam_world::seed::labelled(base, &format!("{experiment}/{mission}/{run}"))
}

/// Runs `job` on every element of `jobs` over up to `threads` threads, the results in
/// the order of `jobs` ([`crate::parallel::run_in_order`]); `progress(done)` after each.
pub(crate) fn run_parallel<J: Sync, R: Send>(
    jobs: &[J],
    threads: usize,
    job: impl Fn(&J) -> R + Sync,
    progress: impl Fn(usize) + Sync,
) -> Vec<R> {
    run_in_order(jobs, threads, job, |_| false, |done, _| progress(done))
        .into_iter()
        .flatten()
        .collect()
}
