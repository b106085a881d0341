//! roam messages as Foxglove messages: pure functions, no I/O.
//!
//! Everything is drawn in one frame, [`FRAME`], whose axes are roam's world metres (the
//! frame the map's `origin` is given in), with z up. Grids keep roam's cell values
//! exactly; scene entities get one colour per kind, the colours of `roam demo`'s picture.
//!
//! Names and ids from the messages become entity ids, labels and metadata only through
//! [`shown`] (escaped, cut), and lists from them are drawn up to a bound, so a message
//! cannot put control characters in the app or make a drawing without end.

use std::collections::VecDeque;

use foxglove::bytes::Bytes;
use foxglove::messages::packed_element_field::NumericType;
use foxglove::messages::{
    line_primitive, scene_entity_deletion, Color, CubePrimitive, Grid, KeyValuePair, LinePrimitive,
    PackedElementField, Point3, Pose, Quaternion, SceneEntity, SceneEntityDeletion, SceneUpdate,
    SpherePrimitive, TextPrimitive, Timestamp, Vector2, Vector3,
};
use roam_proto::cells::Dtype;
use roam_proto::controller::{Mission, MAX_WAYPOINTS};
use roam_proto::localization::PositionEstimate;
use roam_proto::map::{GridMeta, Layer};
use roam_proto::sim::{GroundTruth, NamedPoint};

use crate::wire::shown;

/// The frame every roam message is drawn in: world metres, z up.
pub const FRAME: &str = "map";

/// The name of the one field of every grid.
pub const GRID_FIELD: &str = "value";

/// The colour of the robots' true positions and driven paths (as in `roam demo`'s picture).
pub const DRIVEN: Color = rgb(220, 20, 20);
/// The colour of the planned paths (the mission's waypoints).
pub const PLANNED: Color = rgb(30, 90, 220);
/// The colour of the anchors.
pub const ANCHOR: Color = rgb(140, 0, 200);
/// The colour of the position estimates and their uncertainty ellipses.
pub const ESTIMATE: Color = rgb(255, 150, 0);

const fn rgb(r: u8, g: u8, b: u8) -> Color {
    Color {
        r: r as f64 / 255.0,
        g: g as f64 / 255.0,
        b: b as f64 / 255.0,
        a: 1.0,
    }
}

fn with_alpha(color: Color, a: f64) -> Color {
    Color { a, ..color }
}

/// The diameter of a robot's marker, metres.
pub const ROBOT_SIZE_M: f64 = 0.4;
/// The edge of an anchor's cube, metres.
pub const ANCHOR_SIZE_M: f64 = 0.3;
/// Path line thickness, screen pixels.
const LINE_PX: f64 = 3.0;
/// How many standard deviations the estimate's ellipse spans on each side.
pub const ELLIPSE_SIGMAS: f64 = 2.0;
/// The largest ellipse diameter drawn, metres (a nearly singular CRB would fill the scene).
pub const ELLIPSE_MAX_M: f64 = 50.0;
/// The most waypoint cubes drawn for one mission: a longer mission gets a cube at every
/// k-th waypoint (k as small as keeps it within this), its line through all of them.
pub const MISSION_CUBES: usize = 1000;
/// The most anchors drawn.
pub const MAX_ANCHORS: usize = 256;
/// The most anchor names listed in an estimate's `anchors_used`.
pub const ANCHORS_LISTED: usize = 32;

/// The Foxglove topic of a map layer.
pub fn layer_topic(layer: &str) -> String {
    format!("/map/{layer}")
}

/// Why a layer cannot be drawn.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum ConvertError {
    #[error("layer '{layer}' has {cells} cells but its size is {width} x {height}")]
    CellCount {
        layer: String,
        cells: usize,
        width: u32,
        height: u32,
    },
}

fn vector3(x: f64, y: f64, z: f64) -> Vector3 {
    Vector3 { x, y, z }
}

/// A rotation about z by `yaw` radians.
pub fn yaw_quaternion(yaw: f64) -> Quaternion {
    let half = yaw / 2.0;
    Quaternion {
        x: 0.0,
        y: 0.0,
        z: half.sin(),
        w: half.cos(),
    }
}

fn pose(x: f64, y: f64, z: f64, yaw: f64) -> Pose {
    Pose {
        position: Some(vector3(x, y, z)),
        orientation: Some(yaw_quaternion(yaw)),
    }
}

fn numeric_type(dtype: Dtype) -> NumericType {
    match dtype {
        Dtype::I8 => NumericType::Int8,
        Dtype::U8 => NumericType::Uint8,
        Dtype::F32 => NumericType::Float32,
    }
}

/// A map layer as a `foxglove.Grid` in [`FRAME`]: the grid's corner at the layer's
/// `origin` (rotated by its yaw), square cells of its resolution, row 0 at the origin as
/// in roam (and ROS). One field, [`GRID_FIELD`], holds the cells unchanged: i8 occupancy
/// as ROS values (-1 unknown, 0 free … 100 occupied), u8 scores, f32 values (+∞ where
/// the PEB is unbounded).
pub fn grid(layer: &Layer, timestamp: Timestamp) -> Result<Grid, ConvertError> {
    let meta: &GridMeta = &layer.meta;
    if layer.cells.len() as u64 != meta.cell_count() {
        return Err(ConvertError::CellCount {
            layer: layer.name.clone(),
            cells: layer.cells.len(),
            width: meta.width,
            height: meta.height,
        });
    }
    let dtype = layer.cells.dtype();
    let cell_stride = dtype.size() as u32;
    Ok(Grid {
        timestamp: Some(timestamp),
        frame_id: FRAME.to_owned(),
        pose: Some(pose(meta.origin.x, meta.origin.y, 0.0, meta.origin.yaw)),
        column_count: meta.width,
        cell_size: Some(Vector2 {
            x: meta.resolution,
            y: meta.resolution,
        }),
        row_stride: meta.width * cell_stride,
        cell_stride,
        fields: vec![PackedElementField {
            name: GRID_FIELD.to_owned(),
            offset: 0,
            r#type: numeric_type(dtype) as i32,
        }],
        data: Bytes::from(layer.cells.to_le_bytes()),
    })
}

fn metadata(pairs: &[(&str, String)]) -> Vec<KeyValuePair> {
    pairs
        .iter()
        .map(|(key, value)| KeyValuePair {
            key: (*key).to_owned(),
            value: value.clone(),
        })
        .collect()
}

fn entity(id: String, timestamp: Timestamp) -> SceneEntity {
    SceneEntity {
        timestamp: Some(timestamp),
        frame_id: FRAME.to_owned(),
        id,
        ..SceneEntity::default()
    }
}

fn label(text: &str, at: [f64; 2], z: f64, color: Color) -> TextPrimitive {
    TextPrimitive {
        pose: Some(pose(at[0], at[1], z, 0.0)),
        billboard: true,
        font_size: 14.0,
        scale_invariant: true,
        color: Some(color),
        text: text.to_owned(),
    }
}

fn sphere(at: [f64; 2], diameter: f64, color: Color) -> SpherePrimitive {
    SpherePrimitive {
        pose: Some(pose(at[0], at[1], diameter / 2.0, 0.0)),
        size: Some(vector3(diameter, diameter, diameter)),
        color: Some(color),
    }
}

fn line(points: impl Iterator<Item = [f64; 2]>, z: f64, color: Color) -> LinePrimitive {
    LinePrimitive {
        r#type: line_primitive::Type::LineStrip as i32,
        pose: Some(pose(0.0, 0.0, 0.0, 0.0)),
        thickness: LINE_PX,
        scale_invariant: true,
        points: points
            .map(|p| Point3 {
                x: p[0],
                y: p[1],
                z,
            })
            .collect(),
        color: Some(color),
        ..LinePrimitive::default()
    }
}

fn delete(id: String, timestamp: Timestamp) -> SceneEntityDeletion {
    SceneEntityDeletion {
        timestamp: Some(timestamp),
        r#type: scene_entity_deletion::Type::MatchingId as i32,
        id,
    }
}

/// A robot's true position (`/robots/truth`): entity `truth/<robot>`, a sphere and its name.
pub fn truth(t: &GroundTruth, timestamp: Timestamp) -> SceneUpdate {
    let robot = shown(&t.robot);
    let mut e = entity(format!("truth/{robot}"), timestamp);
    e.spheres.push(sphere(t.at, ROBOT_SIZE_M, DRIVEN));
    e.texts.push(label(
        &robot,
        t.at,
        ROBOT_SIZE_M + 0.3,
        with_alpha(DRIVEN, 1.0),
    ));
    e.metadata = metadata(&[
        ("step", t.step.to_string()),
        ("sim_time_s", fixed(t.time_s, 3)),
    ]);
    SceneUpdate {
        entities: vec![e],
        ..SceneUpdate::default()
    }
}

/// A number from the wire with `decimals` decimals when it is of a sane size, else in
/// scientific notation ([`roam_proto::number`]): a forged 1e300 is not 300 digits of
/// metadata.
fn fixed(x: f64, decimals: usize) -> String {
    if x.abs() < 1e12 {
        format!("{x:.decimals$}")
    } else {
        roam_proto::number(x).to_string()
    }
}

/// The axes of the `sigmas`-σ ellipse of a 2 × 2 covariance: the two diameters (metres,
/// larger first) and the direction of the first, radians. `None` when the matrix is not
/// a covariance (not finite or not positive semi-definite).
pub fn covariance_ellipse(cov: [[f64; 2]; 2], sigmas: f64) -> Option<(f64, f64, f64)> {
    let (a, b, c) = (cov[0][0], (cov[0][1] + cov[1][0]) / 2.0, cov[1][1]);
    if ![a, b, c].iter().all(|v| v.is_finite()) || a < 0.0 || c < 0.0 {
        return None;
    }
    let mean = (a + c) / 2.0;
    let spread = (((a - c) / 2.0).powi(2) + b * b).sqrt();
    let (l1, l2) = (mean + spread, (mean - spread).max(0.0));
    let angle = 0.5 * (2.0 * b).atan2(a - c);
    let diameter = |l: f64| (2.0 * sigmas * l.sqrt()).min(ELLIPSE_MAX_M);
    Some((diameter(l1), diameter(l2), angle))
}

/// A robot's position estimate (`/robots/estimate`): entity `estimate/<robot>`, a small
/// sphere at the estimate and, when the CRB is known, its [`ELLIPSE_SIGMAS`]-σ ellipse
/// (the CRB is the estimate's covariance). A degraded estimate is drawn faint.
pub fn estimate(p: &PositionEstimate, timestamp: Timestamp) -> SceneUpdate {
    let mut e = entity(format!("estimate/{}", shown(&p.robot)), timestamp);
    let color = if p.degraded {
        with_alpha(ESTIMATE, 0.35)
    } else {
        ESTIMATE
    };
    e.spheres
        .push(sphere(p.position, ROBOT_SIZE_M / 2.0, color));
    if let Some((d1, d2, angle)) = p
        .crb
        .and_then(|crb| covariance_ellipse(crb, ELLIPSE_SIGMAS))
    {
        e.spheres.push(SpherePrimitive {
            pose: Some(pose(p.position[0], p.position[1], 0.02, angle)),
            size: Some(vector3(d1.max(0.01), d2.max(0.01), 0.02)),
            color: Some(with_alpha(ESTIMATE, 0.3)),
        });
    }
    e.metadata = metadata(&[
        ("step", p.step.to_string()),
        ("sim_time_s", fixed(p.time_s, 3)),
        (
            "peb_m",
            p.peb_m.map_or("unbounded".to_owned(), |v| fixed(v, 4)),
        ),
        ("degraded", p.degraded.to_string()),
        ("anchors_used", listed(&p.anchors_used, ANCHORS_LISTED)),
    ]);
    SceneUpdate {
        entities: vec![e],
        ..SceneUpdate::default()
    }
}

/// Up to `max` names, each [`shown`], comma-separated, and how many more there were.
fn listed(names: &[String], max: usize) -> String {
    let mut text = names
        .iter()
        .take(max)
        .map(|n| shown(n))
        .collect::<Vec<_>>()
        .join(",");
    if names.len() > max {
        text.push_str(&format!(" (+{} more)", names.len() - max));
    }
    text
}

/// The entity id of a robot's mission.
pub fn mission_id(robot: &str) -> String {
    format!("mission/{}", shown(robot))
}

/// Deletes the entity of a robot's mission (stopped, or no longer kept).
pub fn mission_deleted(robot: &str, timestamp: Timestamp) -> SceneUpdate {
    SceneUpdate {
        deletions: vec![delete(mission_id(robot), timestamp)],
        ..SceneUpdate::default()
    }
}

/// A robot's planned path (`/robots/mission`): entity `mission/<robot>`, a line through
/// its waypoints (at most [`MAX_WAYPOINTS`], the controller's limit) and a small cube at
/// each, or at every k-th when there are more than [`MISSION_CUBES`] (metadata
/// `cube_every`). An empty mission (the robot is stopped) deletes the entity.
pub fn mission(m: &Mission, timestamp: Timestamp) -> SceneUpdate {
    if m.waypoints.is_empty() {
        return mission_deleted(&m.robot, timestamp);
    }
    let waypoints = &m.waypoints[..m.waypoints.len().min(MAX_WAYPOINTS)];
    let mut e = entity(mission_id(&m.robot), timestamp);
    e.lines.push(line(waypoints.iter().copied(), 0.03, PLANNED));
    let every = waypoints.len().div_ceil(MISSION_CUBES);
    e.cubes
        .extend(waypoints.iter().step_by(every).map(|w| CubePrimitive {
            pose: Some(pose(w[0], w[1], 0.03, 0.0)),
            size: Some(vector3(0.1, 0.1, 0.1)),
            color: Some(PLANNED),
        }));
    let mut meta = vec![
        ("mission", shown(&m.id)),
        ("waypoints", m.waypoints.len().to_string()),
    ];
    if every > 1 {
        meta.push(("cube_every", every.to_string()));
    }
    e.metadata = metadata(&meta);
    SceneUpdate {
        entities: vec![e],
        ..SceneUpdate::default()
    }
}

/// The anchors (`/anchors`): entity `anchors`, a cube and a name at each (at most
/// [`MAX_ANCHORS`]).
pub fn anchors(points: &[NamedPoint], timestamp: Timestamp) -> SceneUpdate {
    let mut e = entity("anchors".to_owned(), timestamp);
    for a in points.iter().take(MAX_ANCHORS) {
        e.cubes.push(CubePrimitive {
            pose: Some(pose(a.at[0], a.at[1], ANCHOR_SIZE_M / 2.0, 0.0)),
            size: Some(vector3(ANCHOR_SIZE_M, ANCHOR_SIZE_M, ANCHOR_SIZE_M)),
            color: Some(ANCHOR),
        });
        e.texts
            .push(label(&shown(&a.name), a.at, ANCHOR_SIZE_M + 0.3, ANCHOR));
    }
    SceneUpdate {
        entities: vec![e],
        ..SceneUpdate::default()
    }
}

/// The path one robot drove: its true positions, thinned and bounded. A point closer
/// than `min_step_m` to the last kept one is skipped; past `max_points` the oldest go.
#[derive(Debug, Clone)]
pub struct DrivenPath {
    points: VecDeque<[f64; 2]>,
    max_points: usize,
    min_step_m: f64,
}

impl DrivenPath {
    pub fn new(max_points: usize, min_step_m: f64) -> Self {
        DrivenPath {
            points: VecDeque::new(),
            max_points: max_points.max(2),
            min_step_m,
        }
    }

    /// Adds a true position; returns whether the path changed.
    pub fn push(&mut self, at: [f64; 2]) -> bool {
        if !(at[0].is_finite() && at[1].is_finite()) {
            return false;
        }
        if let Some(last) = self.points.back() {
            if (at[0] - last[0]).hypot(at[1] - last[1]) < self.min_step_m {
                return false;
            }
        }
        if self.points.len() == self.max_points {
            self.points.pop_front();
        }
        self.points.push_back(at);
        true
    }

    pub fn points(&self) -> impl Iterator<Item = [f64; 2]> + '_ {
        self.points.iter().copied()
    }

    pub fn len(&self) -> usize {
        self.points.len()
    }

    pub fn is_empty(&self) -> bool {
        self.points.is_empty()
    }
}

/// Deletes the entity of a robot's driven path (no longer kept).
pub fn driven_deleted(robot: &str, timestamp: Timestamp) -> SceneUpdate {
    SceneUpdate {
        deletions: vec![delete(format!("driven/{}", shown(robot)), timestamp)],
        ..SceneUpdate::default()
    }
}

/// The driven paths (`/robots/driven`): entity `driven/<robot>` per robot, a line.
pub fn driven<'a>(
    paths: impl Iterator<Item = (&'a str, &'a DrivenPath)>,
    timestamp: Timestamp,
) -> SceneUpdate {
    let entities = paths
        .filter(|(_, path)| !path.is_empty())
        .map(|(robot, path)| {
            let mut e = entity(format!("driven/{}", shown(robot)), timestamp);
            e.lines.push(line(path.points(), 0.02, DRIVEN));
            e
        })
        .collect();
    SceneUpdate {
        entities,
        ..SceneUpdate::default()
    }
}

#[cfg(test)]
mod tests;
