//! The live view (a Foxglove WebSocket server, an MCAP recording) served while a demo
//! drives.

use roam_stack::stack::Stack;
use tokio_util::sync::CancellationToken;

use super::error::DemoError;
use super::options::LiveView;

/// Serves the live view (when asked for) while `drive` runs on `stack`, then stops the
/// view and the stack whatever `drive` returned.
pub(crate) async fn with_live_view<T>(
    stack: Stack,
    view: &LiveView,
    progress: &(dyn Fn(&str) + Sync),
    drive: impl AsyncFnOnce(&Stack) -> Result<T, DemoError>,
) -> Result<T, DemoError> {
    let view_cancel = CancellationToken::new();
    let view = match start_view(&stack, view, &view_cancel, progress).await {
        Ok(view) => view,
        Err(e) => {
            let _ = stack.shutdown().await;
            return Err(e);
        }
    };
    let result = drive(&stack).await;
    view_cancel.cancel();
    let viewed = match view {
        Some(view) => view.join().await.map(|_| ()),
        None => Ok(()),
    };
    let _ = stack.shutdown().await;
    let report = result?;
    viewed?;
    Ok(report)
}

/// Starts the live view on the stack's router session when `--view` or `--record` asks
/// for it (`roam_view`: maps, robots, anchors, planned and driven paths).
async fn start_view(
    stack: &Stack,
    view: &LiveView,
    cancel: &CancellationToken,
    progress: &(dyn Fn(&str) + Sync),
) -> Result<Option<roam_view::ViewHandle>, DemoError> {
    if view.listen.is_none() && view.record.is_none() {
        return Ok(None);
    }
    let config = roam_view::ViewConfig {
        root: stack.root.clone(),
        listen: view.listen,
        mcap: view.record.clone(),
        access: view.access.clone(),
    };
    let view = roam_view::run(stack.router.session.clone(), config, cancel.clone()).await?;
    if let Some(url) = view.websocket_url() {
        progress(&format!(
            "live view: in the Foxglove app, Open connection -> Foxglove WebSocket -> {url}"
        ));
    }
    if let Some(path) = view.mcap_path() {
        progress(&format!("recording to {}", path.display()));
    }
    Ok(Some(view))
}
