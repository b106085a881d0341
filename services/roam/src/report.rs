//! The stack's report: what `roam stack --once` prints and writes after fetching every
//! layer through Zenoh, as any client would.

use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

use roam_map_server::grid::Grid;
use roam_map_server::render::render_map;
use roam_map_server::store::{INFORMATION, OCCUPANCY};
use roam_proto::cells::Cells;
use roam_proto::keys;
use roam_proto::map::{Layer, LayerList};
use roam_runtime::{ClientError, Requester};
use serde::Serialize;

/// One layer as the report shows it.
#[derive(Debug, Clone, Serialize)]
pub struct LayerSummary {
    pub name: String,
    pub version: u64,
    pub width: u32,
    pub height: u32,
    pub resolution: f64,
    pub dtype: &'static str,
    /// Milliseconds for the `get` and the decode of this layer.
    pub get_ms: f64,
}

/// The report of a stack run.
#[derive(Debug, Clone, Serialize)]
pub struct StackReport {
    pub root: String,
    pub router: String,
    pub layers: Vec<LayerSummary>,
    pub warnings: Vec<String>,
    pub picture: Option<PathBuf>,
}

#[derive(Debug, thiserror::Error)]
pub enum ReportError {
    #[error(transparent)]
    Client(#[from] ClientError),
    #[error("cannot write {path}: {reason}")]
    Write { path: PathBuf, reason: String },
}

/// Fetches every layer from the map server through Zenoh, and draws the world to
/// `<out_dir>/world.png` (occupancy with the information map tinted over it).
pub async fn build(
    requester: &Requester,
    root: &str,
    router: &str,
    out_dir: &Path,
) -> Result<StackReport, ReportError> {
    let list: LayerList = requester
        .request::<LayerList, LayerList>(&keys::map_index(root), None)
        .await?;
    let mut layers = Vec::new();
    let mut occupancy = None;
    let mut information = None;
    for info in &list.layers {
        let started = Instant::now();
        let layer: Layer = requester
            .request::<Layer, Layer>(&keys::map_layer(root, &info.name), None)
            .await?;
        let get_ms = ms(started.elapsed());
        layers.push(LayerSummary {
            name: layer.name.clone(),
            version: layer.version,
            width: layer.meta.width,
            height: layer.meta.height,
            resolution: layer.meta.resolution,
            dtype: layer.cells.dtype().as_str(),
            get_ms,
        });
        match (layer.name.as_str(), layer.cells) {
            (OCCUPANCY, Cells::I8(cells)) => {
                occupancy = Some(Grid {
                    meta: layer.meta,
                    cells,
                })
            }
            (INFORMATION, Cells::U8(cells)) => {
                information = Some(Grid {
                    meta: layer.meta,
                    cells,
                })
            }
            _ => {}
        }
    }
    let picture = match &occupancy {
        Some(occ) => {
            std::fs::create_dir_all(out_dir).map_err(|e| write_error(out_dir, e))?;
            let path = out_dir.join("world.png");
            let scale = (800 / occ.meta.width.max(occ.meta.height)).clamp(1, 8);
            render_map(occ, information.as_ref(), scale)
                .save(&path)
                .map_err(|e| ReportError::Write {
                    path: path.clone(),
                    reason: e.to_string(),
                })?;
            Some(path)
        }
        None => None,
    };
    Ok(StackReport {
        root: root.to_owned(),
        router: router.to_owned(),
        layers,
        warnings: list.warnings,
        picture,
    })
}

fn write_error(path: &Path, e: std::io::Error) -> ReportError {
    ReportError::Write {
        path: path.to_owned(),
        reason: e.to_string(),
    }
}

pub fn ms(d: Duration) -> f64 {
    d.as_secs_f64() * 1000.0
}

impl std::fmt::Display for StackReport {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        writeln!(
            f,
            "roam stack under '{}', router {}",
            self.root, self.router
        )?;
        writeln!(
            f,
            "{:<14} {:>7} {:>11} {:>10} {:>5} {:>9}",
            "layer", "version", "cells", "m/cell", "type", "get ms"
        )?;
        for l in &self.layers {
            writeln!(
                f,
                "{:<14} {:>7} {:>11} {:>10.3} {:>5} {:>9.2}",
                l.name,
                l.version,
                format!("{}x{}", l.width, l.height),
                l.resolution,
                l.dtype,
                l.get_ms
            )?;
        }
        for w in &self.warnings {
            writeln!(f, "warning: {w}")?;
        }
        if let Some(p) = &self.picture {
            writeln!(f, "picture: {}", p.display())?;
        }
        Ok(())
    }
}
