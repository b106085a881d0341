//! What the executive hears: the mission clock, the robot's estimates, the
//! controller's status on the robot, and the world (the map server's inflated and
//! information layers) it thins and scores paths on.

use std::sync::{Arc, Mutex};

use roam_runtime::lock;
use std::time::{Duration, Instant};

use roam_planner::params::GaParams;
use roam_planner::resolution::PAPER_RESOLUTION_M;
use roam_planner::world::World;
use roam_proto::cells::Cells;
use roam_proto::controller::ControllerStatus;
use roam_proto::localization::PositionEstimate;
use roam_proto::map::Layer;
use roam_proto::map::{INFLATED_LAYER as INFLATED, INFORMATION_LAYER as INFORMATION};
use roam_proto::sim::SimClock;
use roam_proto::ErrorCode;
use roam_proto::{decode, keys};
use roam_runtime::{ClientError, Requester};
use roam_world::grid::Grid;
use tokio_util::sync::CancellationToken;
use zenoh::sample::Sample;

use crate::error::ExecutiveError;

/// The mission clock: the sim's when it publishes one, wall time otherwise.
#[derive(Debug)]
pub(crate) struct Clock {
    started: Instant,
    first: Option<(Instant, f64)>,
    latest: Option<(Instant, f64)>,
}

impl Clock {
    /// Whether the sim's clock has been heard (else the clock is wall time).
    pub(crate) fn heard(&self) -> bool {
        self.latest.is_some()
    }

    pub(crate) fn now_s(&self) -> f64 {
        match self.latest {
            Some((_, sim)) => sim,
            None => self.started.elapsed().as_secs_f64(),
        }
    }

    /// An input stamped `time_s` on the sim's clock came: the clock is at least there
    /// (the estimate of a step can overtake the step's clock on its way through the
    /// router). Without a sim clock heard, nothing changes.
    pub(crate) fn heard_at(&mut self, time_s: f64) {
        if let Some((_, latest)) = self.latest {
            if time_s.is_finite() && time_s > latest {
                self.latest = Some((Instant::now(), time_s));
            }
        }
    }

    /// Mission seconds per wall second, measured; 1 until half a second was seen.
    pub(crate) fn rate(&self) -> f64 {
        match (self.first, self.latest) {
            (Some((w0, s0)), Some((w1, s1))) => {
                let wall = w1.duration_since(w0).as_secs_f64();
                if wall >= 0.5 {
                    ((s1 - s0) / wall).max(1.0)
                } else {
                    1.0
                }
            }
            _ => 1.0,
        }
    }
}

async fn fetch_world(requester: &Requester, root: &str) -> Result<World, ExecutiveError> {
    let inflated: Layer = requester
        .request::<Layer, Layer>(&keys::map_layer(root, INFLATED), None)
        .await?;
    let information: Layer = requester
        .request::<Layer, Layer>(&keys::map_layer(root, INFORMATION), None)
        .await?;
    let Cells::I8(occ) = inflated.cells else {
        return Err(ExecutiveError::Layer(INFLATED, "not i8 cells".into()));
    };
    let Cells::U8(info) = information.cells else {
        return Err(ExecutiveError::Layer(INFORMATION, "not u8 cells".into()));
    };
    // The planner's grid, not the map's: the window's own fastest path from here (its
    // last-safe-moment check, every few seconds per robot) would search all 864,000
    // cells of a 5 cm warehouse map, where the planner's 0.2 m grid has 54,000. The
    // batch's executive works on that grid too, so live and batch decide alike.
    let planning = PAPER_RESOLUTION_M.max(inflated.meta.resolution);
    World::at_resolution(
        &Grid {
            meta: inflated.meta,
            cells: occ,
        },
        &Grid {
            meta: information.meta,
            cells: info,
        },
        GaParams::default().heuristic_compression,
        planning,
    )
    .map_err(|e| ExecutiveError::Layer(INFORMATION, e.to_string()))
}

/// The map server's world, asked for again every [`WORLD_RETRY`] until it answers: in
/// a stack started all at once (compose, systemd at boot) the executive may be up before
/// the map server, and a supervisor restarting it in a loop would only add noise.
pub(crate) async fn wait_for_world(
    requester: &Requester,
    root: &str,
    cancel: &CancellationToken,
) -> Result<World, ExecutiveError> {
    loop {
        match fetch_world(requester, root).await {
            Ok(world) => return Ok(world),
            Err(ExecutiveError::Client(e)) if transient(&e) => {
                tracing::warn!("waiting for the map server: {e}");
            }
            Err(e) => return Err(e),
        }
        tokio::select! {
            _ = cancel.cancelled() => return Err(ExecutiveError::Cancelled),
            _ = tokio::time::sleep(WORLD_RETRY) => {}
        }
    }
}

/// Whether asking again may help: nobody answered, Zenoh failed, or the service said
/// so. A refusal or an undecodable reply (another root, another protocol) will not
/// change by waiting.
fn transient(e: &ClientError) -> bool {
    match e {
        ClientError::NoReply { .. } | ClientError::Zenoh { .. } => true,
        ClientError::Refused(reply) => {
            matches!(reply.code, ErrorCode::Unavailable | ErrorCode::Busy)
        }
        ClientError::Decode { .. } => false,
    }
}

/// How often the executive asks again for a world the map server did not give.
const WORLD_RETRY: Duration = Duration::from_secs(1);

/// Everything the executive listens to.
pub(crate) struct Inputs {
    pub(crate) clock: Arc<Mutex<Clock>>,
    pub(crate) estimates:
        zenoh::pubsub::Subscriber<zenoh::handlers::FifoChannelHandler<zenoh::sample::Sample>>,
    pub(crate) statuses:
        zenoh::pubsub::Subscriber<zenoh::handlers::FifoChannelHandler<zenoh::sample::Sample>>,
    _clock: zenoh::pubsub::Subscriber<()>,
    robot: String,
    estimate_key: String,
    status_key: String,
}

/// Largest estimate or controller status decoded, bytes (each is a few hundred).
const MAX_INPUT_BYTES: usize = 64 * 1024;

impl Inputs {
    /// The estimate in `sample` when it is this robot's: heard on exactly the robot's
    /// key (not a wildcard a stranger put on, such as `robot/**/estimate`) and naming
    /// the robot in its body. Anything else is ignored.
    pub(crate) fn estimate(&self, sample: &Sample) -> Option<PositionEstimate> {
        let e: PositionEstimate = own(sample, &self.estimate_key)?;
        if e.robot != self.robot {
            return None;
        }
        lock(&self.clock).heard_at(e.time_s);
        Some(e)
    }

    /// The controller's status in `sample` when it is on this robot, as
    /// [`Inputs::estimate`].
    pub(crate) fn status(&self, sample: &Sample) -> Option<ControllerStatus> {
        let s: ControllerStatus = own(sample, &self.status_key)?;
        (s.robot == self.robot).then_some(s)
    }
}

fn own<T: roam_proto::Message>(sample: &Sample, key: &str) -> Option<T> {
    if sample.key_expr().as_str() != key || sample.payload().len() > MAX_INPUT_BYTES {
        return None;
    }
    decode(&sample.payload().to_bytes()).ok()
}

pub(crate) async fn listen(
    session: &zenoh::Session,
    root: &str,
    robot: &str,
) -> Result<Inputs, ExecutiveError> {
    let clock = Arc::new(Mutex::new(Clock {
        started: Instant::now(),
        first: None,
        latest: None,
    }));
    let shared = clock.clone();
    let clock_sub = session
        .declare_subscriber(keys::sim_clock(root))
        .callback(move |sample| {
            if let Ok(c) = decode::<SimClock>(&sample.payload().to_bytes()) {
                let mut clock = lock(&shared);
                let now = (Instant::now(), c.time_s);
                clock.first.get_or_insert(now);
                clock.latest = Some(now);
            }
        })
        .await
        .map_err(|e| ExecutiveError::Zenoh(e.to_string()))?;
    let estimate_key = keys::robot_estimate(root, robot);
    let status_key = keys::robot_controller(root, robot);
    let estimates = session
        .declare_subscriber(&estimate_key)
        .await
        .map_err(|e| ExecutiveError::Zenoh(e.to_string()))?;
    let statuses = session
        .declare_subscriber(&status_key)
        .await
        .map_err(|e| ExecutiveError::Zenoh(e.to_string()))?;
    Ok(Inputs {
        clock,
        estimates,
        statuses,
        _clock: clock_sub,
        robot: robot.to_owned(),
        estimate_key,
        status_key,
    })
}
