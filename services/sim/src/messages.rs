//! The sim's reports as wire messages (`roam_proto::sim`).

use roam_proto::cells::Cells;
use roam_proto::map::{GridMeta, Origin};
use roam_proto::sim::{
    AnchorRange, GroundTruth, LocalObservation, NamedPoint, RangeScan, RobotEventKind, RobotEvents,
};

use crate::event::Event;
use crate::sim::{RobotReport, Sim};
use crate::world::Obstacle;

/// The messages of one robot in one step.
#[derive(Debug, Clone)]
pub struct RobotMessages {
    pub ranges: RangeScan,
    pub truth: GroundTruth,
    pub observation: Option<LocalObservation>,
    pub events: Option<RobotEvents>,
}

fn obstacle_name(obstacle: &Obstacle) -> String {
    match obstacle {
        Obstacle::Wall => "wall".into(),
        Obstacle::Block(name) => format!("block:{name}"),
        Obstacle::Walker(name) => format!("walker:{name}"),
        Obstacle::Object(zone) => format!("object:{zone}"),
        Obstacle::OffMap => "off_map".into(),
    }
}

/// One event on the wire.
pub fn event_message(event: &Event) -> RobotEventKind {
    match event {
        Event::SpeedClipped {
            requested_m,
            allowed_m,
        } => RobotEventKind::SpeedClipped {
            requested_m: *requested_m,
            allowed_m: *allowed_m,
        },
        Event::Collision {
            target,
            stopped_at,
            cell,
            obstacle,
        } => RobotEventKind::Collision {
            target: *target,
            stopped_at: *stopped_at,
            cell: *cell,
            obstacle: obstacle_name(obstacle),
        },
        Event::Displaced { from, to, by } => RobotEventKind::Displaced {
            from: *from,
            to: *to,
            by: obstacle_name(by),
        },
        Event::Trapped { by } => RobotEventKind::Trapped {
            by: obstacle_name(by),
        },
    }
}

/// A robot's report as the messages the sim publishes.
pub fn robot_messages(sim: &Sim, step: u64, time_s: f64, report: &RobotReport) -> RobotMessages {
    let anchors = sim.anchors();
    let ranges = RangeScan {
        robot: report.name.clone(),
        step,
        time_s,
        ranges: report
            .readings
            .ranges
            .iter()
            .filter_map(|r| {
                anchors.get(r.anchor).map(|a| AnchorRange {
                    anchor: a.name.clone(),
                    at: a.at,
                    range_m: r.range_m,
                })
            })
            .collect(),
    };
    // A unicycle's heading (`report.readings.heading_rad`) is not on the wire yet:
    // `GroundTruth` has no field for it, and adding one (optional, serde default) also
    // means the live view's own `GroundTruth` literals (services/view) take it.
    let truth = GroundTruth {
        robot: report.name.clone(),
        step,
        time_s,
        at: report.readings.truth,
    };
    let map = sim.scenario().occupancy.meta;
    let observation = report
        .readings
        .observation
        .as_ref()
        .map(|o| LocalObservation {
            robot: report.name.clone(),
            step,
            time_s,
            at: report.readings.truth,
            x0: o.x0,
            y0: o.y0,
            meta: GridMeta {
                width: o.width,
                height: o.height,
                resolution: map.resolution,
                origin: Origin {
                    x: map.origin.x + f64::from(o.x0) * map.resolution,
                    y: map.origin.y + f64::from(o.y0) * map.resolution,
                    yaw: 0.0,
                },
            },
            cells: Cells::I8(o.cells.clone()),
        });
    let events = (!report.events.is_empty()).then(|| RobotEvents {
        robot: report.name.clone(),
        step,
        events: report.events.iter().map(event_message).collect(),
    });
    RobotMessages {
        ranges,
        truth,
        observation,
        events,
    }
}

/// Robots at their true positions, and the anchors.
pub fn points(sim: &Sim) -> (Vec<NamedPoint>, Vec<NamedPoint>) {
    let robots = sim
        .robots()
        .map(|r| NamedPoint {
            name: r.name().to_owned(),
            at: r.position(),
        })
        .collect();
    let anchors = sim
        .anchors()
        .iter()
        .map(|a| NamedPoint {
            name: a.name.clone(),
            at: a.at,
        })
        .collect();
    (robots, anchors)
}
