//! Locking shared state: a service's, or the slots of runs spread over threads.

use std::sync::{Mutex, MutexGuard};

/// Locks `mutex`, taking the state even when a thread panicked while holding it.
///
/// A service's shared state (its caches, counters, the latest estimates) is plain data
/// that every update leaves whole, so a panic elsewhere in a handler does not make it
/// unusable; refusing every later request for it would turn one bug into an outage.
pub fn lock<T>(mutex: &Mutex<T>) -> MutexGuard<'_, T> {
    mutex
        .lock()
        .unwrap_or_else(|poisoned| poisoned.into_inner())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_poisoned_lock_still_gives_the_state() {
        let m = Mutex::new(1);
        let _ = std::panic::catch_unwind(|| {
            let _held = m.lock();
            panic!("a handler panicked");
        });
        assert!(m.is_poisoned());
        *lock(&m) += 1;
        assert_eq!(*lock(&m), 2);
    }
}
