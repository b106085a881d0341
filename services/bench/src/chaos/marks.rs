//! Acked map updates, written through the day and checked at its end: a writer (as the
//! mapper or an operator writes) sets one cell of a layer of its own after another,
//! each to a value no other write gives, and keeps the ones the map server acked. At the
//! end every acked write must be in the layer: an ack is the map server's promise that
//! the write is kept (it is on disk before the ack), through its own crash too.

use std::time::Duration;

use roam_proto::cells::Cells;
use roam_proto::map::{CellWrite, GridMeta, Layer, LayerChange, LayerUpdate, Origin, UpdateAck};
use roam_proto::{keys, ErrorCode};
use roam_runtime::{ClientError, Requester};
use serde::Serialize;
use tokio_util::sync::CancellationToken;

/// The marks layer's side, cells: at most `SIDE`² marks in a day.
const SIDE: u32 = 64;
/// The name of the writer's own layer.
pub(super) const MARKS_LAYER: &str = "chaos_marks";

/// What the writer did and what the layer kept.
#[derive(Debug, Clone, Default, Serialize)]
pub struct MarksOutcome {
    /// Writes sent.
    pub sent: u64,
    /// Writes the map server acked.
    pub acked: u64,
    /// Acked writes not in the layer at the end of the day.
    pub acked_lost: u64,
    /// Writes refused as stale (the writer's version was behind) and sent again.
    pub stale: u64,
    /// Writes with no answer (the map server or the link was down).
    pub unanswered: u64,
}

fn cell(k: u32) -> (u32, u32) {
    (k % SIDE, k / SIDE)
}

/// Writes a mark every `every` until `stop`; the marks acked, by index.
pub(super) async fn write_marks(
    requester: Requester,
    root: String,
    every: Duration,
    stop: CancellationToken,
) -> (MarksOutcome, Vec<u32>) {
    let key = keys::map_update(&root, MARKS_LAYER);
    let mut outcome = MarksOutcome::default();
    let mut acked = Vec::new();
    let mut version = 0;
    // The layer, made once (version 1).
    while version == 0 && !stop.is_cancelled() {
        let create = LayerUpdate {
            base_version: 0,
            change: LayerChange::Replace {
                meta: GridMeta {
                    width: SIDE,
                    height: SIDE,
                    resolution: 1.0,
                    origin: Origin::default(),
                },
                cells: Cells::F32(vec![0.0; (SIDE * SIDE) as usize]),
            },
            world: None,
        };
        match requester
            .request::<LayerUpdate, UpdateAck>(&key, Some(&create))
            .await
        {
            Ok(ack) => version = ack.version,
            Err(_) => tokio::time::sleep(every).await,
        }
    }
    let mut k = 0;
    while k < SIDE * SIDE && !stop.is_cancelled() {
        let (x, y) = cell(k);
        let write = LayerUpdate {
            base_version: version,
            change: LayerChange::SetCells {
                cells: vec![CellWrite {
                    x,
                    y,
                    value: f64::from(k + 1),
                }],
            },
            world: None,
        };
        outcome.sent += 1;
        match requester
            .request::<LayerUpdate, UpdateAck>(&key, Some(&write))
            .await
        {
            Ok(ack) => {
                version = ack.version;
                outcome.acked += 1;
                acked.push(k);
                k += 1;
            }
            Err(ClientError::Refused(reply)) if reply.code == ErrorCode::StaleVersion => {
                outcome.stale += 1;
                if let Ok(layer) = requester
                    .request::<Layer, Layer>(&keys::map_layer(&root, MARKS_LAYER), None)
                    .await
                {
                    version = layer.version;
                }
                continue;
            }
            Err(_) => outcome.unanswered += 1,
        }
        tokio::select! {
            _ = tokio::time::sleep(every) => {}
            _ = stop.cancelled() => {}
        }
    }
    (outcome, acked)
}

/// How many of the `acked` marks are not in the layer now; every one when the layer
/// cannot be read.
pub(super) async fn lost(requester: &Requester, root: &str, acked: &[u32]) -> u64 {
    let layer = requester
        .request::<Layer, Layer>(&keys::map_layer(root, MARKS_LAYER), None)
        .await;
    let Ok(Layer {
        cells: Cells::F32(values),
        meta,
        ..
    }) = layer
    else {
        return acked.len() as u64;
    };
    acked
        .iter()
        .filter(|&&k| {
            let (x, y) = cell(k);
            let i = (y * meta.width + x) as usize;
            values.get(i).copied() != Some((k + 1) as f32)
        })
        .count() as u64
}
