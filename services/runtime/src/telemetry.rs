//! Tracing, configured from `RUST_LOG`.

use tracing_subscriber::EnvFilter;

/// The filter used when `RUST_LOG` is not set: roam at `info`, Zenoh's chatter at `warn`.
pub const DEFAULT_FILTER: &str = "info,zenoh=warn,zenoh_transport=warn,zenoh_link_tcp=warn";

/// Installs a tracing subscriber that writes to stderr, filtered by `RUST_LOG` (or
/// [`DEFAULT_FILTER`]). Calling it twice is harmless: the second call does nothing.
pub fn init() {
    let filter =
        EnvFilter::try_from_default_env().unwrap_or_else(|_| EnvFilter::new(DEFAULT_FILTER));
    let _ = tracing_subscriber::fmt()
        .with_env_filter(filter)
        .with_writer(std::io::stderr)
        .try_init();
}
