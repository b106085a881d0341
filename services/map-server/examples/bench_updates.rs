//! What a one-cell update costs the map server's store: latency and bytes written to
//! disk, for a maximum-size (4096 × 4096) layer persisted in a data dir.
//!
//! ```sh
//! cargo run --release -p roam-map-server --example bench_updates -- [updates] [dir]
//! ```
//!
//! Two layers are measured: a free f32 layer (`peb`-like, 67 MB of cells) and
//! `occupancy` (i8, with `inflated` derived from it). Bytes are the process's own
//! `write` calls (`wchar` in `/proc/self/io`), so they count what the store asked the
//! file system to write whatever the file system; the data dir's size after the run is
//! printed too. Prints one JSON object.

use std::path::{Path, PathBuf};
use std::time::Instant;

use roam_map_server::persist::DataDir;
use roam_map_server::store::{DerivedParams, LayerStore, DEFAULT_LIMITS};
use roam_proto::cells::Cells;
use roam_proto::map::{CellWrite, GridMeta, LayerChange, LayerUpdate, Origin};
use roam_world::grid::{occupancy, Grid};

const SIDE: u32 = 4096;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let mut args = std::env::args().skip(1);
    let updates: usize = args.next().map_or(Ok(20), |a| a.parse())?;
    let dir = args.next().map_or_else(
        || std::env::temp_dir().join("roam-bench-updates"),
        PathBuf::from,
    );
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir)?;
    let meta = GridMeta {
        width: SIDE,
        height: SIDE,
        resolution: 0.25,
        origin: Origin::default(),
    };
    let mut store = LayerStore::new(
        DEFAULT_LIMITS,
        DerivedParams::default(),
        Some(DataDir::open(&dir, DEFAULT_LIMITS.max_layer_cells)?),
    );
    store.load_map(Grid::filled(meta, occupancy::FREE), None, None)?;
    let create = LayerUpdate {
        base_version: 0,
        change: LayerChange::Replace {
            meta,
            cells: Cells::F32(vec![0.0; (SIDE * SIDE) as usize]),
        },
        world: None,
    };
    store.apply("peb", &create)?;

    let free = measure(&mut store, "peb", updates, 0.5)?;
    let occ = measure(&mut store, "occupancy", updates, 100.0)?;
    let on_disk = dir_bytes(&dir.join("layers"))?;
    println!(
        "{{\"side\": {SIDE}, \"updates\": {updates}, \"free_f32\": {free}, \"occupancy_i8\": {occ}, \"data_dir_bytes_after\": {on_disk}}}"
    );
    let _ = std::fs::remove_dir_all(&dir);
    Ok(())
}

/// `updates` one-cell updates to `layer`, each on a different cell: latency median and
/// max in ms, bytes written per update.
fn measure(
    store: &mut LayerStore,
    layer: &str,
    updates: usize,
    value: f64,
) -> Result<String, Box<dyn std::error::Error>> {
    let mut latencies = Vec::with_capacity(updates);
    let written_before = wchar()?;
    for i in 0..updates {
        let update = LayerUpdate {
            base_version: store.version(layer),
            change: LayerChange::SetCells {
                cells: vec![CellWrite {
                    x: 100 + 37 * i as u32 % 3000,
                    y: 200 + 53 * i as u32 % 3000,
                    value,
                }],
            },
            world: None,
        };
        let started = Instant::now();
        store.apply(layer, &update)?;
        latencies.push(started.elapsed().as_secs_f64() * 1e3);
    }
    let written = wchar()? - written_before;
    latencies.sort_by(f64::total_cmp);
    let median = latencies[latencies.len() / 2];
    let max = latencies[latencies.len() - 1];
    Ok(format!(
        "{{\"latency_median_ms\": {median:.2}, \"latency_max_ms\": {max:.2}, \"bytes_written_per_update\": {}}}",
        written / updates as u64
    ))
}

/// Bytes this process has passed to `write` so far.
fn wchar() -> Result<u64, Box<dyn std::error::Error>> {
    let io = std::fs::read_to_string("/proc/self/io")?;
    io.lines()
        .find_map(|l| l.strip_prefix("wchar: "))
        .ok_or("no wchar in /proc/self/io")?
        .trim()
        .parse()
        .map_err(Into::into)
}

fn dir_bytes(dir: &Path) -> std::io::Result<u64> {
    let mut total = 0;
    for entry in std::fs::read_dir(dir)? {
        total += entry?.metadata()?.len();
    }
    Ok(total)
}
