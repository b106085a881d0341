//! SIGINT and SIGTERM as a cancellation: containers and systemd stop a service with
//! SIGTERM, a person with Ctrl-C, and both must lead to the same graceful stop.

use tokio_util::sync::CancellationToken;

/// Returns when the process receives SIGINT or SIGTERM (or Ctrl-C off Unix).
pub async fn wait_for_stop_signal() {
    #[cfg(unix)]
    {
        use tokio::signal::unix::{signal, SignalKind};
        match signal(SignalKind::terminate()) {
            Ok(mut term) => {
                tokio::select! {
                    _ = tokio::signal::ctrl_c() => {}
                    _ = term.recv() => {}
                }
            }
            Err(e) => {
                tracing::warn!("cannot listen for SIGTERM ({e}); only Ctrl-C stops this process");
                let _ = tokio::signal::ctrl_c().await;
            }
        }
    }
    #[cfg(not(unix))]
    {
        let _ = tokio::signal::ctrl_c().await;
    }
}

/// A cancellation token that is cancelled by the first SIGINT or SIGTERM.
pub fn cancel_on_signal() -> CancellationToken {
    let token = CancellationToken::new();
    let trigger = token.clone();
    tokio::spawn(async move {
        wait_for_stop_signal().await;
        tracing::info!("stop signal received, shutting down");
        trigger.cancel();
    });
    token
}
