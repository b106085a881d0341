//! Runs an experiment's independent runs over several threads without letting the
//! thread count change a figure.

use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::Mutex;

/// Runs `job` on every element of `jobs` over up to `threads` scoped threads and returns
/// the results in the order of `jobs`, whatever order they finished in: anything summed
/// over them is the same bit for bit whatever the thread count. `progress(done, job)`
/// is called after each job. Once `stop(&result)` holds for a result, the threads take
/// no further jobs; the jobs never run are `None` (the jobs already started still
/// finish, so the first stopping result in order is always there).
pub fn run_in_order<J: Sync, R: Send>(
    jobs: &[J],
    threads: usize,
    job: impl Fn(&J) -> R + Sync,
    stop: impl Fn(&R) -> bool + Sync,
    progress: impl Fn(usize, &J) + Sync,
) -> Vec<Option<R>> {
    let threads = threads.clamp(1, jobs.len().max(1));
    let next = AtomicUsize::new(0);
    let done = AtomicUsize::new(0);
    let slots: Mutex<Vec<Option<R>>> = Mutex::new((0..jobs.len()).map(|_| None).collect());
    std::thread::scope(|scope| {
        for _ in 0..threads {
            scope.spawn(|| loop {
                let i = next.fetch_add(1, Ordering::Relaxed);
                let Some(j) = jobs.get(i) else {
                    return;
                };
                let result = job(j);
                let stopping = stop(&result);
                if let Some(slot) = roam_world::lock::lock(&slots).get_mut(i) {
                    *slot = Some(result);
                }
                progress(done.fetch_add(1, Ordering::Relaxed) + 1, j);
                if stopping {
                    next.store(jobs.len(), Ordering::Relaxed);
                }
            });
        }
    });
    slots.into_inner().unwrap_or_else(|p| p.into_inner())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn results_come_back_in_the_jobs_order_whatever_the_threads() {
        let jobs: Vec<u64> = (0..200).collect();
        let square = |j: &u64| {
            // Later jobs finish first on several threads.
            std::thread::sleep(std::time::Duration::from_micros(200 - j));
            j * j
        };
        let one = run_in_order(&jobs, 1, square, |_| false, |_, _| {});
        let four = run_in_order(&jobs, 4, square, |_| false, |_, _| {});
        assert_eq!(one, four);
        assert_eq!(four[17], Some(289));
    }

    #[test]
    fn a_stopping_result_ends_the_work_and_the_rest_is_none() {
        let jobs: Vec<u32> = (0..50).collect();
        let out = run_in_order(&jobs, 1, |&j| j, |&r| r == 10, |_, _| {});
        assert_eq!(out[10], Some(10));
        assert!(out[11..].iter().all(Option::is_none));
        assert!(out[..10].iter().all(Option::is_some));
    }
}
