//! Messages of the localization / CRB service (paper 002 §2).
//!
//! JSON has no infinity, so an unbounded PEB (a singular Fisher information) travels
//! as `null` (`None`); grids of PEB travel as f32 cells, where infinity is a value.

use serde::{Deserialize, Serialize};

use crate::cells::Cells;
use crate::codec::Message;
use crate::map::GridMeta;
use crate::sim::NamedPoint;

/// A robot's position estimate from its TOA ranges, on `<root>/robot/<id>/estimate`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PositionEstimate {
    pub robot: String,
    pub step: u64,
    pub time_s: f64,
    /// World metres.
    pub position: [f64; 2],
    /// The Cramér–Rao bound at the estimate, m² (row-major 2 × 2), which is also the
    /// estimate's covariance (WLS attains the bound at convergence); `None` when the
    /// Fisher information is singular.
    pub crb: Option<[[f64; 2]; 2]>,
    /// Position error bound √tr(CRB), metres; `None` when unbounded.
    pub peb_m: Option<f64>,
    /// The anchors whose ranges were used.
    pub anchors_used: Vec<String>,
    /// Too few or badly placed anchors, or no convergence: the estimate is the prior.
    pub degraded: bool,
}

impl Message for PositionEstimate {
    const KIND: &'static str = "position_estimate";
}

/// A grid region in the world.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Region {
    pub meta: GridMeta,
}

/// Where to evaluate PEB / CRB: a list of points or a grid region.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case", deny_unknown_fields)]
pub enum PebWhere {
    Points(Vec<[f64; 2]>),
    Region(GridMeta),
}

/// A PEB query on `<root>/localization/peb`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PebQuery {
    #[serde(rename = "where")]
    pub at: PebWhere,
    /// The anchor constellation; the service's configured one when absent.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub anchors: Option<Vec<NamedPoint>>,
    /// Also return the gradient of PEB at each point (points only).
    #[serde(default)]
    pub gradient: bool,
    /// Also return the CRB's three distinct entries over a region (regions only).
    #[serde(default)]
    pub crb: bool,
}

impl Message for PebQuery {
    const KIND: &'static str = "peb_query";
}

/// PEB, CRB and optionally the PEB gradient at one point.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PebAt {
    pub at: [f64; 2],
    pub peb_m: Option<f64>,
    pub crb: Option<[[f64; 2]; 2]>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub gradient: Option<[f64; 2]>,
}

/// The answer to a [`PebQuery`].
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case", deny_unknown_fields)]
pub enum PebReply {
    Points(Vec<PebAt>),
    /// PEB in metres per cell, f32, infinity where unbounded; with `crb` asked for, the
    /// CRB's xx, xy and yy entries per cell (m², infinity on the diagonal and 0 off it
    /// where unbounded).
    Field {
        meta: GridMeta,
        cells: Cells,
        #[serde(default, skip_serializing_if = "Option::is_none")]
        crb: Option<CrbCells>,
    },
}

/// The CRB over a region, one f32 grid per distinct entry of the 2 × 2 matrix.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CrbCells {
    pub xx: Cells,
    pub xy: Cells,
    pub yy: Cells,
}

impl Message for PebReply {
    const KIND: &'static str = "peb_reply";
}
