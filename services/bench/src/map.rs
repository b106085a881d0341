//! `roam bench map`: how long a large layer takes end to end through Zenoh.
//!
//! Boots a router and a map server in process (as `roam stack` does), loads a generated
//! map of about 1.7 million cells (a full-size warehouse at 5 cm), then measures from a
//! separate client session:
//! - `get`: the query, the map server's reply, and the client's decode of the layer;
//! - `publish`: a `put` of the same encoded layer from one client session to a
//!   subscriber on another, through the router, including the subscriber's decode.
//!
//! Medians over `iterations` runs, in milliseconds, printed as JSON.

use std::path::Path;
use std::time::{Duration, Instant};

use roam_proto::cells::Cells;
use roam_proto::map::{GridMeta, Layer, Origin};
use roam_proto::{decode, encode, keys};
use roam_runtime::{Requester, SessionArgs};
use roam_world::grid::{occupancy, Grid};
use roam_world::ros_map::{self, SaveParams};
use serde::Serialize;

use crate::{setup, BenchError};
use zenoh::qos::CongestionControl;

use crate::ms;
use roam_stack::stack::{Stack, StackOptions};

/// What `roam bench map --json` prints.
#[derive(Debug, Clone, Serialize)]
pub struct MapBench {
    pub cells: u64,
    /// Bytes of the encoded layer message.
    pub message_bytes: usize,
    pub iterations: usize,
    pub get_median_ms: f64,
    pub get_max_ms: f64,
    pub publish_median_ms: f64,
    pub publish_max_ms: f64,
    /// Encode and decode alone, no network.
    pub encode_median_ms: f64,
    pub decode_median_ms: f64,
}

/// A warehouse-like occupancy grid: walls around, rows of shelves, unknown outside.
pub fn warehouse_grid(width: u32, height: u32) -> Grid<i8> {
    let meta = GridMeta {
        width,
        height,
        resolution: 0.05,
        origin: Origin::default(),
    };
    let mut grid = Grid::filled(meta, occupancy::FREE);
    let (w, h) = (width as usize, height as usize);
    for y in 0..h {
        for x in 0..w {
            let wall = x < 2 || y < 2 || x >= w - 2 || y >= h - 2;
            let shelf = (x / 40) % 3 == 1 && (y % 200) > 20 && (y % 200) < 180;
            if wall || shelf {
                grid.cells[y * w + x] = occupancy::OCCUPIED;
            }
        }
    }
    grid
}

fn median(samples: &mut [f64]) -> f64 {
    samples.sort_by(f64::total_cmp);
    samples.get(samples.len() / 2).copied().unwrap_or(f64::NAN)
}

fn max(samples: &[f64]) -> f64 {
    samples.iter().copied().fold(f64::NAN, f64::max)
}

/// Runs the map benchmark with a `side × side` map.
pub async fn map(side: u32, iterations: usize, work_dir: &Path) -> Result<MapBench, BenchError> {
    let setup = |e: String| BenchError::Setup(e);
    let grid = warehouse_grid(side, side);
    let yaml = work_dir.join("warehouse.yaml");
    ros_map::save(&grid, &yaml, SaveParams::default()).map_err(|e| setup(e.to_string()))?;
    let stack = Stack::start(
        StackOptions {
            root: Some("roam-bench".into()),
            map: Some(yaml),
            planners: 1,
            ..StackOptions::default()
        },
        Duration::from_secs(30),
    )
    .await
    .map_err(|e| setup(e.to_string()))?;
    let result = measure(&stack, &grid, iterations).await;
    stack.shutdown().await.map_err(|e| setup(e.to_string()))?;
    result
}

async fn measure(
    stack: &Stack,
    grid: &Grid<i8>,
    iterations: usize,
) -> Result<MapBench, BenchError> {
    let open = |endpoint: &str| {
        let args = SessionArgs::client_of(endpoint);
        async move {
            let config = args.zenoh_config(None).map_err(setup)?;
            roam_runtime::session::open(config).await.map_err(setup)
        }
    };
    let client = open(&stack.router.endpoint).await?;
    let requester = Requester::new(client.clone(), Duration::from_secs(10));
    let layer_key = keys::map_layer(&stack.root, "occupancy");
    let mut gets = Vec::with_capacity(iterations);
    for _ in 0..iterations {
        let started = Instant::now();
        let layer: Layer = requester.request::<Layer, Layer>(&layer_key, None).await?;
        gets.push(ms(started.elapsed()));
        if layer.cells.len() != grid.cells.len() {
            return Err(BenchError::Setup(format!(
                "got {} cells, expected {}",
                layer.cells.len(),
                grid.cells.len()
            )));
        }
    }

    let layer = Layer {
        name: "bench".into(),
        version: 1,
        meta: grid.meta,
        derived_from: None,
        cells: Cells::I8(grid.cells.clone()),
    };
    let mut encodes = Vec::new();
    let mut decodes = Vec::new();
    let mut bytes = Vec::new();
    for _ in 0..iterations {
        let started = Instant::now();
        bytes = encode(&layer);
        encodes.push(ms(started.elapsed()));
        let started = Instant::now();
        let back: Layer = decode(&bytes).map_err(setup)?;
        decodes.push(ms(started.elapsed()));
        std::hint::black_box(back);
    }

    let listener = open(&stack.router.endpoint).await?;
    let publish_key = keys::map_layer(&stack.root, "bench");
    let subscriber = listener
        .declare_subscriber(&publish_key)
        .await
        .map_err(setup)?;
    let publisher = client
        .declare_publisher(&publish_key)
        .congestion_control(CongestionControl::Block)
        .await
        .map_err(setup)?;
    if !crate::matched(&publisher, Duration::from_secs(10)).await {
        return Err(BenchError::Setup(
            "the subscriber never matched the publisher".into(),
        ));
    }
    let mut publishes = Vec::with_capacity(iterations);
    let wait = Duration::from_secs(10);
    for _ in 0..iterations {
        let started = Instant::now();
        publisher.put(bytes.clone()).await.map_err(setup)?;
        let sample = tokio::time::timeout(wait, subscriber.recv_async())
            .await
            .map_err(|_| BenchError::Lost(wait))?
            .map_err(setup)?;
        let received: Layer = decode(&sample.payload().to_bytes()).map_err(setup)?;
        publishes.push(ms(started.elapsed()));
        std::hint::black_box(received);
    }
    drop(publisher);
    drop(subscriber);
    let _ = listener.close().await;
    let _ = client.close().await;
    Ok(MapBench {
        cells: grid.cells.len() as u64,
        message_bytes: bytes.len(),
        iterations,
        get_max_ms: max(&gets),
        get_median_ms: median(&mut gets),
        publish_max_ms: max(&publishes),
        publish_median_ms: median(&mut publishes),
        encode_median_ms: median(&mut encodes),
        decode_median_ms: median(&mut decodes),
    })
}
