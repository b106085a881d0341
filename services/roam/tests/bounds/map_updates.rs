//! Concurrent big updates within the map server's limits: every one is answered, the map
//! server keeps its router (no liveliness drop), and its memory stays bounded.

use std::time::{Duration, Instant};

use roam_proto::cells::Cells;
use roam_proto::map::{CellWrite, GridMeta, LayerChange, LayerUpdate, Origin, UpdateAck};
use roam_proto::{encode, keys};
use roam_runtime::{ClientError, Requester};

use crate::liveliness::Drops;

/// Concurrent requests of each kind.
pub(crate) const CONCURRENT: usize = 3;
/// How long each may take to be answered.
const ANSWER_WITHIN: Duration = Duration::from_secs(120);

/// A `set_cells` of about `bytes` bytes: more cells than one update may carry, which
/// the map server must refuse without reading them all.
fn set_cells_payload(bytes: usize) -> Vec<u8> {
    let one = CellWrite {
        x: 1,
        y: 1,
        value: 100.0,
    };
    // `{"x":1,"y":1,"value":100.0},` is 28 bytes.
    encode(&LayerUpdate {
        base_version: 1,
        change: LayerChange::SetCells {
            cells: vec![one; bytes / 28],
        },
        world: None,
    })
}

/// A `replace` creating a free layer at the map server's largest size, f32 (about 90 MB,
/// under `max_request_bytes`).
fn replace_payload() -> Vec<u8> {
    let meta = GridMeta {
        width: 4096,
        height: 4096,
        resolution: 0.05,
        origin: Origin::default(),
    };
    encode(&LayerUpdate {
        base_version: 0,
        change: LayerChange::Replace {
            meta,
            cells: Cells::F32(vec![0.5; 4096 * 4096]),
        },
        world: None,
    })
}

/// What the attack measured.
#[derive(Debug)]
pub(crate) struct Outcome {
    pub(crate) requests: usize,
    pub(crate) answered: usize,
    pub(crate) slowest: Duration,
    pub(crate) drops: usize,
}

pub(crate) async fn concurrent_big_updates(session: &zenoh::Session, root: &str) -> Outcome {
    let drops = Drops::watch(session, root, roam_map_server::SERVICE_NAME).await;
    let client = Requester::new(session.clone(), ANSWER_WITHIN);
    let big_set = set_cells_payload(50_000_000);
    let big_replace = replace_payload();
    let mut tasks = Vec::new();
    for i in 0..CONCURRENT {
        for (key, payload) in [
            (keys::map_update(root, "occupancy"), big_set.clone()),
            (
                keys::map_update(root, &format!("big{i}")),
                big_replace.clone(),
            ),
        ] {
            let asker = client.clone();
            tasks.push(tokio::spawn(async move {
                let t = Instant::now();
                let r = asker.request_raw::<UpdateAck>(&key, Some(payload)).await;
                (key, r.map(|_| ()), t.elapsed())
            }));
        }
    }
    drop((big_set, big_replace));
    let requests = tasks.len();
    let mut answered = 0;
    let mut slowest = Duration::ZERO;
    for task in tasks {
        let (key, result, took) = task.await.expect("task");
        slowest = slowest.max(took);
        match result {
            Ok(()) | Err(ClientError::Refused(_)) => answered += 1,
            Err(e) => eprintln!("{key}: no answer after {took:?}: {e}"),
        }
    }
    Outcome {
        requests,
        answered,
        slowest,
        drops: drops.count(),
    }
}
