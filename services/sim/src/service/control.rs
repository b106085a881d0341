//! The `sim/control` queryable: load, reset, step, pause, resume and the robots.

use std::sync::Arc;

use roam_proto::sim::SimControl;
use roam_proto::{keys, ErrorCode, ErrorReply};
use roam_runtime::reply;
use roam_world::load_dirs::Access;
use roam_world::scenario;
use roam_world::DEFAULT_MAX_CELLS;
use zenoh::query::Query;

use crate::sim::Sim;

use super::limits::{
    check_rate, MAX_REQUEST_BYTES, MAX_ROBOT_STEPS_PER_REQUEST, MAX_STEPS_PER_REQUEST,
};
use super::replies::{scenario_error, sim_error};
use super::shared::SimShared;
use super::step::{publish, step_once};

pub(super) async fn answer_control(state: Arc<SimShared>, query: Query) {
    let request = match reply::decode_request::<SimControl>(&query, MAX_REQUEST_BYTES) {
        Ok(r) => r,
        Err(e) => return reply::send_error(&query, &e).await,
    };
    let outcome = control(&state, request).await;
    state.wake.notify_waiters();
    reply::send_result(&query, outcome.map(|()| state.status())).await;
}

/// Loads the scenario a peer named, relative to the load directories. A refusal is
/// logged with the server's paths, and answered with the file as the peer named it.
async fn load(state: &Arc<SimShared>, path: String, seed: u64) -> Result<(), ErrorReply> {
    let dirs = state.load_dirs.clone();
    let loaded = tokio::task::spawn_blocking(move || {
        let file = dirs
            .resolve(&path)
            .map_err(|e| (e.to_string(), e.to_reply(&path)))?;
        let scenario = scenario::load_with(&file, DEFAULT_MAX_CELLS, Access::Within(&dirs))
            .map_err(|e| (e.to_string(), scenario_error(&e, &path, &dirs)))?;
        let sim = Sim::new(&scenario, seed).map_err(|e| (e.to_string(), sim_error(&e)))?;
        Ok((file.display().to_string(), sim))
    })
    .await
    .unwrap_or_else(|e| {
        let reply = ErrorReply::new(ErrorCode::Internal, format!("loading failed: {e}"));
        Err((reply.to_string(), reply))
    });
    let (name, sim) = match loaded {
        Ok(loaded) => loaded,
        Err((detail, reply)) => {
            roam_runtime::limited_warn!(state.warnings, "load", %detail, "refused a scenario load");
            return Err(reply);
        }
    };
    let mut c = state.control();
    c.scenario = name;
    c.sim = sim;
    c.running = false;
    c.pending.clear();
    c.late_steps = 0;
    c.free_steps = 0;
    Ok(())
}

async fn control(state: &Arc<SimShared>, request: SimControl) -> Result<(), ErrorReply> {
    match request {
        SimControl::Load { path, seed } => load(state, path, seed).await?,
        SimControl::Reset { seed } => {
            let mut c = state.control();
            c.sim.reset(seed);
            c.pending.clear();
            c.late_steps = 0;
            c.free_steps = 0;
        }
        SimControl::Step { n } => {
            if n > MAX_STEPS_PER_REQUEST {
                return Err(ErrorReply::limit(
                    "max_steps_per_request",
                    u64::from(MAX_STEPS_PER_REQUEST),
                    u64::from(n),
                    format!("ask for at most {MAX_STEPS_PER_REQUEST} steps per request"),
                ));
            }
            let robots = state.control().sim.robots().count().max(1) as u64;
            let robot_steps = u64::from(n) * robots;
            if robot_steps > MAX_ROBOT_STEPS_PER_REQUEST {
                return Err(ErrorReply::limit(
                    "max_robot_steps_per_request",
                    MAX_ROBOT_STEPS_PER_REQUEST,
                    robot_steps,
                    format!(
                        "{n} steps of {robots} robots is {robot_steps} robot-steps; ask for at most {} steps per request",
                        MAX_ROBOT_STEPS_PER_REQUEST / robots
                    ),
                ));
            }
            let Ok(_request) = state.step_request.try_lock() else {
                return Err(ErrorReply::new(
                    ErrorCode::Busy,
                    "another step request is running; wait for its reply, then step again",
                ));
            };
            let _stepping = state.stepper.lock().await;
            if state.control().running {
                return Err(ErrorReply::new(
                    ErrorCode::InvalidRequest,
                    "the sim is free-running; pause it before stepping it in lock-step",
                ));
            }
            for _ in 0..n {
                if state.control().running {
                    break;
                }
                let stepped = step_once(state)?;
                publish(state, stepped).await;
            }
        }
        SimControl::Pause => state.control().running = false,
        SimControl::Resume { rate } => {
            check_rate(rate)?;
            let mut c = state.control();
            c.running = true;
            c.rate = rate;
            c.late_steps = 0;
            c.free_steps = 0;
        }
        SimControl::AddRobot { name, at } => {
            keys::check_name("robot name", &name)
                .map_err(|e| ErrorReply::new(ErrorCode::InvalidRequest, e.to_string()))?;
            state
                .control()
                .sim
                .add_robot(&name, at)
                .map_err(|e| sim_error(&e))?;
        }
        SimControl::RemoveRobot { name } => {
            let mut c = state.control();
            c.sim.remove_robot(&name).map_err(|e| sim_error(&e))?;
            c.pending.remove(&name);
        }
        SimControl::Status => {}
    }
    Ok(())
}
