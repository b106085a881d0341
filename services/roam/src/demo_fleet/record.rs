//! What `roam demo --fleet` records from the wire while the executives drive: the
//! robots' true positions, every observation and the objects the sim lands and clears
//! (how soon the fleet sees each change), the controller's statuses, the sim's events,
//! and every sim minute the mapper's `occupied_now` scored against the world.

use std::sync::{Arc, Mutex};
use std::time::Duration;

use roam_experiments::reproduce::fleet::events::ChangeLog;
use roam_experiments::reproduce::fleet::measure::{MapSample, PATH_EVERY_STEPS};
use roam_experiments::reproduce::fleet::week::MAP_SAMPLE_S;
use roam_experiments::reproduce::fleet::FleetWorld;
use roam_proto::cells::Cells;
use roam_proto::controller::{ControllerStatus, MissionState};
use roam_proto::map::Layer;
use roam_proto::mapper::OCCUPIED_NOW_LAYER;
use roam_proto::mission::WindowReport;
use roam_proto::sim::{
    GroundTruth, LocalObservation, ObjectTruth, ObjectsTruth, RobotEventKind, RobotEvents,
};
use roam_proto::{decode, keys, Message};
use roam_runtime::{lock, Requester};
use tokio_util::sync::CancellationToken;
use zenoh::pubsub::Subscriber;

use crate::demo::DemoError;

/// What the run records from the wire while the executives drive.
pub(super) struct Recorder {
    pub(super) names: Vec<String>,
    pub(super) shift_s: f64,
    pub(super) step_s: f64,
    /// The newest sim time heard.
    pub(super) now_s: f64,
    pub(super) changes: ChangeLog,
    pub(super) landed: Vec<ObjectTruth>,
    /// Each robot's true positions with their times (the windows' information).
    pub(super) truth: Vec<Vec<(f64, [f64; 2])>>,
    /// Each robot's path for the picture, every [`PATH_EVERY_STEPS`]th step.
    pub(super) paths: Vec<Vec<[f64; 2]>>,
    pub(super) halted_steps: Vec<u64>,
    /// Each robot's last controller state and distance left: said when a window is
    /// given up.
    pub(super) last_status: Vec<Option<(MissionState, Option<f64>)>>,
    /// Each robot's last event from the sim (a collision, a push by a moving obstacle)
    /// and its step: said with the controller's state when a window is given up.
    pub(super) last_event: Vec<Option<(u64, String)>>,
    pub(super) plan_latencies_s: Vec<f64>,
    pub(super) maps: Vec<MapSample>,
}

impl Recorder {
    pub(super) fn robot(&self, name: &str) -> Option<usize> {
        self.names.iter().position(|n| n == name)
    }

    fn truth(&mut self, t: &GroundTruth) {
        let Some(i) = self.robot(&t.robot) else {
            return;
        };
        self.now_s = self.now_s.max(t.time_s);
        // A shift's steps at most: the sim runs a little past the last task.
        let most = (self.shift_s / self.step_s).ceil() as usize + 1024;
        if self.truth[i].len() < most {
            self.truth[i].push((t.time_s, t.at));
        }
        if t.time_s <= self.shift_s && t.step.is_multiple_of(PATH_EVERY_STEPS) {
            self.paths[i].push(t.at);
        }
    }

    pub(super) fn window_truth(&self, robot: usize, report: &WindowReport) -> Vec<[f64; 2]> {
        let end = report.arrival_s.unwrap_or(report.task_start_s);
        self.truth[robot]
            .iter()
            .filter(|(t, _)| *t >= report.began_s && *t <= end)
            .map(|(_, at)| *at)
            .collect()
    }
}

pub(super) type Shared = Arc<Mutex<Recorder>>;

/// A sim event in a few words.
fn event_name(e: &RobotEventKind) -> String {
    match e {
        RobotEventKind::SpeedClipped { .. } => "speed clipped".to_owned(),
        RobotEventKind::Collision { obstacle, .. } => format!("collision with {obstacle}"),
        RobotEventKind::Displaced { by, .. } => format!("pushed by {by}"),
        RobotEventKind::Trapped { by } => format!("trapped by {by}"),
    }
}

/// The subscribers that feed the recorder; dropped, they stop.
pub(super) async fn listen(
    session: &zenoh::Session,
    root: &str,
    recorder: &Shared,
) -> Result<Vec<Subscriber<()>>, DemoError> {
    Ok(vec![
        follow(
            session,
            keys::robot_truth_any(root),
            recorder,
            |r, t: GroundTruth| r.truth(&t),
        )
        .await?,
        follow(
            session,
            keys::robot_observation_any(root),
            recorder,
            |r, o: LocalObservation| r.changes.observe(&o, o.time_s),
        )
        .await?,
        follow(
            session,
            keys::sim_objects(root),
            recorder,
            |r, o: ObjectsTruth| {
                r.changes.update(&o.objects, o.time_s);
                r.landed = o.objects;
            },
        )
        .await?,
        follow(
            session,
            keys::robot_events_any(root),
            recorder,
            |r, e: RobotEvents| {
                if let (Some(i), Some(last)) = (r.robot(&e.robot), e.events.last()) {
                    r.last_event[i] = Some((e.step, event_name(last)));
                }
            },
        )
        .await?,
        follow(
            session,
            keys::robot_controller_any(root),
            recorder,
            |r, c: ControllerStatus| {
                if let Some(i) = r.robot(&c.robot) {
                    if c.state == MissionState::HaltedPeb {
                        r.halted_steps[i] += 1;
                    }
                    r.last_status[i] = Some((c.state, c.distance_left_m));
                }
            },
        )
        .await?,
    ])
}

/// A subscriber on `key` that hands each message that decodes to `record`, under the
/// recorder's lock.
async fn follow<T: Message>(
    session: &zenoh::Session,
    key: String,
    recorder: &Shared,
    record: impl Fn(&mut Recorder, T) + Send + Sync + 'static,
) -> Result<Subscriber<()>, DemoError> {
    let recorder = recorder.clone();
    session
        .declare_subscriber(key)
        .callback(move |sample| {
            if let Ok(message) = decode::<T>(&sample.payload().to_bytes()) {
                record(&mut lock(&recorder), message);
            }
        })
        .await
        .map_err(|e| DemoError::Zenoh(e.to_string()))
}

/// Every sim minute, the mapper's `occupied_now` layer scored against the sim's
/// objects, as the batch scores its mapper's belief ([`MapSample::score`]).
pub(super) async fn sample_maps(
    requester: Requester,
    root: String,
    world: Arc<FleetWorld>,
    recorder: Shared,
    cancel: CancellationToken,
) {
    let mut next_s = MAP_SAMPLE_S;
    let key = keys::map_layer(&root, OCCUPIED_NOW_LAYER);
    loop {
        tokio::select! {
            _ = cancel.cancelled() => return,
            _ = tokio::time::sleep(Duration::from_millis(50)) => {}
        }
        let now_s = lock(&recorder).now_s;
        if now_s < next_s {
            continue;
        }
        next_s += MAP_SAMPLE_S;
        let Ok(layer) = requester.request::<Layer, Layer>(&key, None).await else {
            continue;
        };
        let belief = belief_on_coarse(&world, &layer);
        let truth = world.semi_static_truth(&lock(&recorder).landed);
        if let Ok(sample) = MapSample::score(&world, now_s, &belief, &truth) {
            lock(&recorder).maps.push(sample);
        }
    }
}

/// The layer's P(occupied now) at each coarse cell's centre (0..=100 → 0..1); a cell
/// the layer does not cover is 1/2.
fn belief_on_coarse(world: &FleetWorld, layer: &Layer) -> Vec<f64> {
    let coarse = world.coarse;
    let Cells::I8(cells) = &layer.cells else {
        return vec![0.5; coarse.cell_count() as usize];
    };
    let (w, h) = (coarse.width as usize, coarse.height as usize);
    let mut belief = Vec::with_capacity(w * h);
    for cy in 0..h {
        for cx in 0..w {
            let x = coarse.origin.x + (cx as f64 + 0.5) * coarse.resolution;
            let y = coarse.origin.y + (cy as f64 + 0.5) * coarse.resolution;
            let p = roam_world::grid::world_to_cell(&layer.meta, x, y)
                .and_then(|(lx, ly)| cells.get(ly * layer.meta.width as usize + lx))
                .map_or(0.5, |&v| f64::from(v.clamp(0, 100)) / 100.0);
            belief.push(p);
        }
    }
    belief
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_belief_is_read_at_each_coarse_cells_centre() {
        let Ok(world) = FleetWorld::warehouse() else {
            panic!("the built-in warehouse loads");
        };
        let meta = world.coarse;
        let n = meta.cell_count() as usize;
        let mut cells = vec![0i8; n];
        cells[n - 1] = 100;
        let layer = Layer {
            name: OCCUPIED_NOW_LAYER.into(),
            version: 1,
            meta,
            derived_from: None,
            cells: Cells::I8(cells),
        };
        let belief = belief_on_coarse(&world, &layer);
        assert_eq!(belief.len(), n);
        assert_eq!(belief[n - 1], 1.0);
        assert_eq!(belief[0], 0.0);
    }
}
