//! Everything the services of this test binary log, captured: the attack test checks
//! that no file content and no raw wire data reaches a log, and how much an attack makes
//! the log grow.

use std::io::Write;
use std::sync::{Arc, Mutex, OnceLock};

/// The captured log, as the default format writes it (no colours).
#[derive(Debug, Clone, Default)]
pub(crate) struct Captured(Arc<Mutex<Vec<u8>>>);

impl Captured {
    /// Bytes logged so far.
    pub(crate) fn len(&self) -> usize {
        self.0.lock().map(|b| b.len()).unwrap_or_default()
    }

    /// Waits (at most [`roam_tests::STEP`]) until the log from byte `from` on holds
    /// `needle`: what a service logs is the only trace a subscriber leaves.
    pub(crate) async fn wait_for(&self, from: usize, needle: &str) {
        let until = std::time::Instant::now() + roam_tests::STEP;
        while !self.since(from).contains(needle) {
            assert!(
                std::time::Instant::now() < until,
                "the log never said '{needle}'"
            );
            tokio::time::sleep(std::time::Duration::from_millis(20)).await;
        }
    }

    /// The log from byte `from` on, as text.
    pub(crate) fn since(&self, from: usize) -> String {
        let bytes = self.0.lock().map(|b| b.clone()).unwrap_or_default();
        String::from_utf8_lossy(&bytes[from.min(bytes.len())..]).into_owned()
    }
}

struct Writer(Captured);

impl Write for Writer {
    fn write(&mut self, buf: &[u8]) -> std::io::Result<usize> {
        if let Ok(mut log) = (self.0).0.lock() {
            log.extend_from_slice(buf);
        }
        Ok(buf.len())
    }

    fn flush(&mut self) -> std::io::Result<()> {
        Ok(())
    }
}

/// Installs the capturing subscriber (once per test binary) at the services' default
/// level (`info`, Zenoh at `warn`), before any harness installs its own.
pub(crate) fn capture() -> Captured {
    static CAPTURED: OnceLock<Captured> = OnceLock::new();
    CAPTURED
        .get_or_init(|| {
            let captured = Captured::default();
            let sink = captured.clone();
            let _ = tracing_subscriber::fmt()
                .with_env_filter(tracing_subscriber::EnvFilter::new("info,zenoh=warn"))
                .with_ansi(false)
                .with_writer(move || Writer(sink.clone()))
                .try_init();
            captured
        })
        .clone()
}
