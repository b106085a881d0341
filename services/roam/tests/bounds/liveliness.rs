//! Watching a service's liveliness token while an attack runs: a service that loses its
//! router (its transport closed under load) drops its token, and the drop is seen here.

use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::Arc;

use roam_proto::keys;
use zenoh::sample::SampleKind;

/// Counts the drops of `service`'s liveliness tokens from now on.
pub(crate) struct Drops {
    count: Arc<AtomicUsize>,
    _subscriber: zenoh::pubsub::Subscriber<()>,
}

impl Drops {
    pub(crate) async fn watch(session: &zenoh::Session, root: &str, service: &str) -> Drops {
        let count = Arc::new(AtomicUsize::new(0));
        let seen = count.clone();
        let subscriber = session
            .liveliness()
            .declare_subscriber(keys::liveliness_of(root, service))
            .callback(move |sample| {
                if sample.kind() == SampleKind::Delete {
                    seen.fetch_add(1, Ordering::Relaxed);
                }
            })
            .await
            .expect("liveliness subscriber");
        Drops {
            count,
            _subscriber: subscriber,
        }
    }

    pub(crate) fn count(&self) -> usize {
        self.count.load(Ordering::Relaxed)
    }
}
