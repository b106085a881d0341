//! roam's layers, plans, estimates and paths as ROS 2 messages, and back: a ROS map as a
//! roam occupancy layer, a ROS plan request as a roam plan request.
//!
//! Everything is in one frame, `map`: roam's world metres, z up, the frame the layers'
//! origins are given in.

use roam_proto::cells::Cells;
use roam_proto::localization::PositionEstimate;
use roam_proto::map::{GridMeta, Layer, Origin};
use roam_proto::planner::{GaOverrides, Plan, PlanRequest, PlannerModel, ShortestPathUse};
use roam_proto::{ErrorCode, ErrorReply};

use crate::msg::{
    Covariance, Header, MapMetaData, OccupancyGrid, Path, PlanDowntimeRequest,
    PlanDowntimeResponse, Point, Pose, PoseStamped, PoseWithCovariance, PoseWithCovarianceStamped,
    Quaternion, TfMessage, Time, Transform, TransformStamped, Vector3,
};

/// The one frame roam publishes in.
pub const FRAME: &str = "map";

/// How a layer's values become an OccupancyGrid's 0..100 (and -1 for no value).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Scale {
    /// Already ROS occupancy (i8 -1, 0..=100): copied.
    Occupancy,
    /// Scores 0..=100 (u8): copied, above 100 as 100.
    Score,
    /// Probabilities 0..=1: × 100, rounded.
    Probability,
    /// Metres from 0 to `full_m`: 0..100, at or beyond `full_m` (∞ included) 100.
    Metres { full_m: f64 },
}

/// The PEB at which `/roam/peb` shows 100: a metre of position error bound is already
/// far worse than the controller's goals (paper 002's PEB stays in centimetres where the
/// anchors cover).
pub const PEB_FULL_SCALE_M: f64 = 1.0;

/// The layers roam publishes and how: (layer, relative topic name, scale).
pub const LAYER_TOPICS: [(&str, &str, Scale); 7] = [
    ("occupancy", "map", Scale::Occupancy),
    ("inflated", "roam/inflated", Scale::Occupancy),
    ("information", "roam/information", Scale::Score),
    (
        "peb",
        "roam/peb",
        Scale::Metres {
            full_m: PEB_FULL_SCALE_M,
        },
    ),
    (
        roam_proto::mapper::CHANGE_PROBABILITY_LAYER,
        "roam/change_probability",
        Scale::Probability,
    ),
    (roam_proto::mapper::NEWS_LAYER, "roam/news", Scale::Score),
    (
        roam_proto::mapper::OCCUPIED_NOW_LAYER,
        "roam/occupied_now",
        Scale::Occupancy,
    ),
];

/// Why a conversion was refused.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum ConvertError {
    #[error("the layer has {cells} cells for a {width}x{height} grid")]
    CellCount {
        cells: usize,
        width: u32,
        height: u32,
    },
    #[error("a {width}x{height} map is {cells} cells; roam takes at most {max} (max_layer_cells)")]
    TooManyCells {
        width: u32,
        height: u32,
        cells: u64,
        max: u64,
    },
    #[error("{0}")]
    Invalid(String),
}

fn clamp_score(v: f64) -> i8 {
    if v.is_nan() {
        -1
    } else {
        v.round().clamp(0.0, 100.0) as i8
    }
}

/// A layer as an OccupancyGrid in frame `map`, stamped `stamp`.
pub fn layer_to_grid(
    layer: &Layer,
    scale: Scale,
    stamp: Time,
) -> Result<OccupancyGrid, ConvertError> {
    let meta = layer.meta;
    if layer.cells.len() as u64 != meta.cell_count() {
        return Err(ConvertError::CellCount {
            cells: layer.cells.len(),
            width: meta.width,
            height: meta.height,
        });
    }
    let data: Vec<i8> = match (&layer.cells, scale) {
        (Cells::I8(v), _) => v
            .iter()
            .map(|&c| if c < 0 { -1 } else { c.min(100) })
            .collect(),
        (Cells::U8(v), _) => v.iter().map(|&c| c.min(100) as i8).collect(),
        (Cells::F32(v), Scale::Probability) => v
            .iter()
            .map(|&c| clamp_score(f64::from(c) * 100.0))
            .collect(),
        (Cells::F32(v), Scale::Metres { full_m }) => v
            .iter()
            .map(|&c| {
                let c = f64::from(c);
                if c.is_nan() {
                    -1
                } else {
                    clamp_score(c / full_m * 100.0)
                }
            })
            .collect(),
        (Cells::F32(v), Scale::Occupancy | Scale::Score) => {
            v.iter().map(|&c| clamp_score(f64::from(c))).collect()
        }
    };
    Ok(OccupancyGrid {
        header: Header {
            stamp,
            frame_id: FRAME.to_owned(),
        },
        info: MapMetaData {
            map_load_time: stamp,
            resolution: meta.resolution as f32,
            width: meta.width,
            height: meta.height,
            origin: Pose {
                position: Point {
                    x: meta.origin.x,
                    y: meta.origin.y,
                    z: 0.0,
                },
                orientation: Quaternion::from_yaw(meta.origin.yaw),
            },
        },
        data,
    })
}

/// Checks a received grid's size against `max_cells` from its header alone, before its
/// cells are read or kept: a 10⁹-cell map is refused here, naming the limit.
pub fn check_grid_size(info: &MapMetaData, max_cells: u64) -> Result<(), ConvertError> {
    let cells = u64::from(info.width) * u64::from(info.height);
    if cells > max_cells {
        return Err(ConvertError::TooManyCells {
            width: info.width,
            height: info.height,
            cells,
            max: max_cells,
        });
    }
    Ok(())
}

/// A ROS map as roam's occupancy grid: its placement and its cells (-1 unknown, 0..=100;
/// any other value is refused, as the map server refuses it).
pub fn grid_to_occupancy(
    grid: &OccupancyGrid,
    max_cells: u64,
) -> Result<(GridMeta, Cells), ConvertError> {
    let info = &grid.info;
    check_grid_size(info, max_cells)?;
    let cells = u64::from(info.width) * u64::from(info.height);
    if cells == 0 || grid.data.len() as u64 != cells {
        return Err(ConvertError::CellCount {
            cells: grid.data.len(),
            width: info.width,
            height: info.height,
        });
    }
    let resolution = f64::from(info.resolution);
    if !(resolution.is_finite() && resolution > 0.0) {
        return Err(ConvertError::Invalid(format!(
            "the map's resolution must be a positive number of metres, got {}",
            roam_proto::number(resolution)
        )));
    }
    let p = info.origin.position;
    let q = info.origin.orientation;
    if ![p.x, p.y, p.z, q.x, q.y, q.z, q.w]
        .iter()
        .all(|v| v.is_finite())
    {
        return Err(ConvertError::Invalid(
            "the map's origin must be finite numbers".into(),
        ));
    }
    if let Some((i, bad)) = grid
        .data
        .iter()
        .enumerate()
        .find(|(_, &v)| !(-1..=100).contains(&v))
    {
        return Err(ConvertError::Invalid(format!(
            "occupancy values are -1 (unknown) or 0..=100; cell {i} is {bad}"
        )));
    }
    let meta = GridMeta {
        width: info.width,
        height: info.height,
        resolution,
        origin: Origin {
            x: p.x,
            y: p.y,
            yaw: q.yaw(),
        },
    };
    Ok((meta, Cells::I8(grid.data.clone())))
}

fn header(stamp: Time) -> Header {
    Header {
        stamp,
        frame_id: FRAME.to_owned(),
    }
}

/// Points as a Path, each pose facing the next point (the last one keeps the heading
/// before it).
pub fn path(points: &[[f64; 2]], stamp: Time) -> Path {
    let mut heading = 0.0;
    let poses = points
        .iter()
        .enumerate()
        .map(|(i, p)| {
            if let Some(next) = points.get(i + 1) {
                let (dx, dy) = (next[0] - p[0], next[1] - p[1]);
                if dx != 0.0 || dy != 0.0 {
                    heading = dy.atan2(dx);
                }
            }
            PoseStamped {
                header: header(stamp),
                pose: Pose {
                    position: Point {
                        x: p[0],
                        y: p[1],
                        z: 0.0,
                    },
                    orientation: Quaternion::from_yaw(heading),
                },
            }
        })
        .collect();
    Path {
        header: header(stamp),
        poses,
    }
}

/// The variance put where roam knows nothing: the heading (roam's estimates are
/// positions), and x and y when the CRB is singular (fewer than three anchors).
pub const UNKNOWN_VARIANCE: f64 = 1e9;

/// An estimate as a PoseWithCovarianceStamped: the position, and its CRB (paper 002
/// Eq. 5, which WLS attains) as the x-y block of the covariance; z, roll and pitch are
/// 0 (a planar robot), the heading's variance [`UNKNOWN_VARIANCE`].
pub fn estimate_pose(estimate: &PositionEstimate, stamp: Time) -> PoseWithCovarianceStamped {
    let mut covariance = [0.0; 36];
    match estimate.crb {
        Some(crb) if crb.iter().flatten().all(|v| v.is_finite()) => {
            covariance[0] = crb[0][0];
            covariance[1] = crb[0][1];
            covariance[6] = crb[1][0];
            covariance[7] = crb[1][1];
        }
        _ => {
            covariance[0] = UNKNOWN_VARIANCE;
            covariance[7] = UNKNOWN_VARIANCE;
        }
    }
    covariance[35] = UNKNOWN_VARIANCE;
    PoseWithCovarianceStamped {
        header: header(stamp),
        pose: PoseWithCovariance {
            pose: Pose {
                position: Point {
                    x: estimate.position[0],
                    y: estimate.position[1],
                    z: 0.0,
                },
                orientation: Quaternion::default(),
            },
            covariance: Covariance(covariance),
        },
    }
}

/// A robot's body frame under `/tf`: `<robot>/base_link` (REP-105's name, prefixed by
/// the robot as multi-robot Nav2 setups do).
pub fn base_link(robot: &str) -> String {
    format!("{robot}/base_link")
}

/// An estimate as the transform `map → <robot>/base_link`: the position, z 0, and the
/// identity rotation (roam's estimates are positions; the heading is not estimated).
pub fn estimate_transform(robot: &str, estimate: &PositionEstimate, stamp: Time) -> TfMessage {
    TfMessage {
        transforms: vec![TransformStamped {
            header: header(stamp),
            child_frame_id: base_link(robot),
            transform: Transform {
                translation: Vector3 {
                    x: estimate.position[0],
                    y: estimate.position[1],
                    z: 0.0,
                },
                rotation: Quaternion::default(),
            },
        }],
    }
}

/// Why a pose from ROS 2 is not a position roam can plan with.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum PoseError {
    /// In a frame other than `map`.
    Frame(String),
    /// Not finite coordinates.
    NotFinite(String),
}

impl PoseError {
    pub fn message(&self) -> &str {
        match self {
            PoseError::Frame(m) | PoseError::NotFinite(m) => m,
        }
    }
}

/// A pose's position, checked: finite, and in frame `map` (or no frame); `what` names
/// it in the error (`start`, `goal`).
pub fn pose_position(what: &str, pose: &PoseStamped) -> Result<[f64; 2], PoseError> {
    let frame = pose.header.frame_id.as_str();
    if !(frame.is_empty() || frame == FRAME || frame == "/map") {
        return Err(PoseError::Frame(format!(
            "{what} is in frame '{}'; roam plans in frame 'map' (give poses in 'map')",
            roam_proto::excerpt::excerpt_n(frame, 64)
        )));
    }
    let p = pose.pose.position;
    if !(p.x.is_finite() && p.y.is_finite()) {
        return Err(PoseError::NotFinite(format!(
            "{what} must be finite coordinates in metres, got ({}, {})",
            roam_proto::number(p.x),
            roam_proto::number(p.y)
        )));
    }
    Ok([p.x, p.y])
}

/// [`pose_position`], refused as an invalid request.
fn position(what: &str, pose: &PoseStamped) -> Result<[f64; 2], ErrorReply> {
    pose_position(what, pose)
        .map_err(|e| ErrorReply::new(ErrorCode::InvalidRequest, e.message().to_owned()))
}

/// The deadline a PlanDowntime request without one (0) gets, seconds.
pub const DEFAULT_DEADLINE_S: f64 = 5.0;

/// A PlanDowntime request as roam's plan request, or the refusal that goes back in the
/// response's error fields.
pub fn plan_downtime_request(request: &PlanDowntimeRequest) -> Result<PlanRequest, ErrorReply> {
    let start = position("start", &request.start)?;
    let goal = position("goal", &request.goal)?;
    if !(request.budget_s.is_finite() && request.budget_s > 0.0) {
        return Err(ErrorReply::new(
            ErrorCode::InvalidRequest,
            format!(
                "budget_s must be a positive number of seconds, got {}",
                roam_proto::number(request.budget_s)
            ),
        ));
    }
    if !(request.deadline_s.is_finite() && request.deadline_s >= 0.0) {
        return Err(ErrorReply::new(
            ErrorCode::InvalidRequest,
            format!(
                "deadline_s must be 0 (the default, {DEFAULT_DEADLINE_S} s) or a positive number of seconds, got {}",
                roam_proto::number(request.deadline_s)
            ),
        ));
    }
    let model = match request.model.as_str() {
        "" | "model1" => PlannerModel::Model1,
        "anytime" => PlannerModel::Anytime,
        "model0" => PlannerModel::Model0,
        "model2" => PlannerModel::Model2,
        "greedy" => PlannerModel::Greedy,
        "shortest" => PlannerModel::Shortest,
        other => {
            return Err(ErrorReply::new(
                ErrorCode::InvalidRequest,
                format!(
                    "model '{}' is not one of shortest, model0, model1, model2, greedy, anytime (empty: model1)",
                    roam_proto::excerpt::excerpt_n(other, 64)
                ),
            ))
        }
    };
    Ok(PlanRequest {
        request_id: None,
        cancel_token: None,
        start,
        goal,
        t_exec_s: request.budget_s,
        deadline_s: if request.deadline_s == 0.0 {
            DEFAULT_DEADLINE_S
        } else {
            request.deadline_s
        },
        model,
        params: GaOverrides::default(),
        seed: request.seed,
        map_version: None,
        shortest: ShortestPathUse::Omit,
        seed_route: Vec::new(),
    })
}

/// A GetPlan request's start and goal, checked like PlanDowntime's.
pub fn get_plan_ends(
    request: &crate::msg::GetPlanRequest,
) -> Result<([f64; 2], [f64; 2]), ErrorReply> {
    Ok((
        position("start", &request.start)?,
        position("goal", &request.goal)?,
    ))
}

/// A plan as PlanDowntime's response.
pub fn plan_downtime_response(plan: &Plan, stamp: Time) -> PlanDowntimeResponse {
    PlanDowntimeResponse {
        path: path(&plan.points, stamp),
        eta_s: plan.t_eta_s,
        information: plan.distinct_information,
        within_budget: plan.within_budget,
        reaches_goal: plan.reaches_goal,
        error_code: String::new(),
        error_message: String::new(),
    }
}

/// A refusal as PlanDowntime's response: an empty path in frame `map`, the code and the
/// message (with the limit, where one was hit).
pub fn plan_downtime_refusal(error: &ErrorReply, stamp: Time) -> PlanDowntimeResponse {
    PlanDowntimeResponse {
        path: path(&[], stamp),
        error_code: error.code.as_str().to_owned(),
        error_message: match &error.limit {
            Some(limit) => format!(
                "{} (limit {}: at most {}, got {})",
                error.message, limit.name, limit.max, limit.actual
            ),
            None => error.message.clone(),
        },
        ..PlanDowntimeResponse::default()
    }
}

#[cfg(test)]
mod tests;
