//! The snapshot a restart resumes from: read at start, written while the sim steps.

use std::path::{Path, PathBuf};
use std::sync::Arc;

use tokio_util::sync::CancellationToken;

use crate::sim::Sim;
use crate::snapshot::{self, SnapshotError};

use super::config::SimServiceError;
use super::limits::SNAPSHOT_PERIOD;
use super::shared::SimShared;

/// Resumes `sim` from the snapshot at `path` when it is of this scenario and seed; a
/// snapshot of another run is left alone (and overwritten at the first save).
pub(super) fn resume_from(
    sim: &mut Sim,
    name: &str,
    seed: u64,
    path: &Path,
) -> Result<(), SimServiceError> {
    let Some(saved) = snapshot::load(path)? else {
        return Ok(());
    };
    if saved.scenario != name || saved.seed != seed {
        tracing::warn!(
            path = %path.display(), scenario = %saved.scenario, seed = saved.seed,
            "the snapshot is of another scenario or seed: starting at step 0"
        );
        return Ok(());
    }
    sim.resume(&saved).map_err(|e| SnapshotError::Resume {
        path: path.to_owned(),
        reason: e.to_string(),
    })?;
    tracing::info!(
        path = %path.display(), step = saved.step, robots = saved.robots.len(),
        "resumed from the snapshot"
    );
    Ok(())
}

/// Writes the snapshot every [`SNAPSHOT_PERIOD`] while the step count changes, and once
/// more at shutdown.
pub(super) async fn keep_snapshots(
    state: Arc<SimShared>,
    path: PathBuf,
    cancel: CancellationToken,
) {
    let mut saved_step = None;
    loop {
        let stopping = tokio::select! {
            _ = cancel.cancelled() => true,
            _ = tokio::time::sleep(SNAPSHOT_PERIOD) => false,
        };
        let snap = {
            let c = state.control();
            c.sim.snapshot(&c.scenario)
        };
        if saved_step != Some(snap.step) {
            let target = path.clone();
            let step = snap.step;
            match tokio::task::spawn_blocking(move || snapshot::save(&target, &snap)).await {
                Ok(Ok(())) => saved_step = Some(step),
                Ok(Err(e)) => tracing::warn!("{e}"),
                Err(e) => tracing::warn!("the snapshot writer failed: {e}"),
            }
        }
        if stopping {
            return;
        }
    }
}
