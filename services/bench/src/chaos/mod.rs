//! `roam bench chaos`: the built-in day with every role killed, two links cut and a
//! planner frozen, each on a seeded schedule; what came back, how fast, and what the
//! day lost.
//!
//! The roles run as processes of the `roam` binary behind one router process, as on a
//! site (`roam router`, `roam map-server --data-dir`, two planners, `roam sim
//! --state-file`, localization, the controller, the mapper, the mission executive with a
//! `calibration_file` and a `resume_file`, the ROS 2 node). The bench is their supervisor: it starts again
//! what it killed after the schedule's delay, and whatever exits on its own at once.
//! The planners and the controller reach the router through cuttable links
//! ([`link::Link`]): cutting the planners' is the partition between the executive and
//! the planners, cutting the controller's the one between the controller and the sim.
//!
//! Through the day the bench writes map updates of its own (`marks`) and watches, as a
//! client: after each fault, each role's token and first good answer; across each, the
//! map's layer versions (none may go back); at the end, every acked update in its layer,
//! the derived layers as the map server's recipes give them from their sources, and
//! whether the controller holds the robot. Each window is judged against the faults that
//! struck in it: on time, or late by no more than they lasted.

mod derived;
pub mod link;
mod marks;
pub mod report;
pub mod schedule;
pub mod site;
pub mod stack;
pub mod watch;

use std::collections::BTreeMap;
use std::net::SocketAddr;
use std::path::PathBuf;
use std::time::{Duration, Instant};

use roam_experiments::progress::{Done, Progress};
use roam_proto::controller::MissionState;
use roam_proto::keys;
use roam_proto::sim::{SimControl, SimStatus};
use roam_runtime::SessionArgs;
use roam_stack::router::free_loopback_port;
use tokio_util::sync::CancellationToken;

pub use marks::MarksOutcome;
pub use report::ChaosReport;
use report::{FaultOutcome, RoleRecovery};
use schedule::{Fault, ScheduleSpec};
use site::RoleSpec;
pub use site::{ChaosSite, MAX_FLEET_ROBOTS};
pub use stack::Processes;
use watch::{Answer, Watch};

use crate::{setup, BenchError};

/// The fastest sim the chaos day runs: the executive's and the controller's wall-clock
/// rules (a silent controller after 3 s, a stale estimate after 1 s) cost the robot
/// `rate` times as many sim seconds.
pub const MAX_RATE: f64 = 10.0;
/// The longest cut or freeze, wall seconds.
pub const MAX_HOLD_S: f64 = 60.0;
/// A role killed is started again after a delay in this range, wall seconds.
const RESTART_DELAY_S: (f64, f64) = (0.5, 2.0);
/// How long the bench waits for a role's token or first answer before it records none.
const PATIENCE: Duration = Duration::from_secs(30);
/// The bench's map updates, one every this.
const MARK_EVERY: Duration = Duration::from_millis(500);

/// What a chaos day is run with.
#[derive(Debug, Clone)]
pub struct ChaosOptions {
    pub seed: u64,
    /// Sim seconds per wall second.
    pub rate: f64,
    /// How long each link stays cut, wall seconds (Zenoh's lease is 10 s: a longer cut
    /// ends the sessions across it).
    pub partition_s: f64,
    /// How long the frozen planner stays stopped, wall seconds.
    pub freeze_s: f64,
    /// The `roam` binary whose roles are run.
    pub program: PathBuf,
    /// The built-in day, or the warehouse fleet's shift.
    pub site: ChaosSite,
}

impl ChaosOptions {
    /// Refuses settings outside the named limits.
    pub fn check(&self) -> Result<(), BenchError> {
        if !(self.rate > 0.0 && self.rate <= MAX_RATE) {
            return Err(BenchError::Setup(format!(
                "--rate must be in (0, {MAX_RATE}] sim seconds per second, got {}",
                self.rate
            )));
        }
        for (name, value) in [
            ("--partition-s", self.partition_s),
            ("--freeze-s", self.freeze_s),
        ] {
            if !(value > 0.0 && value <= MAX_HOLD_S) {
                return Err(BenchError::Setup(format!(
                    "{name} must be in (0, {MAX_HOLD_S}] seconds, got {value}"
                )));
            }
        }
        if let ChaosSite::Fleet { robots, shift_s } = self.site {
            if robots == 0 || robots > MAX_FLEET_ROBOTS {
                return Err(BenchError::Setup(format!(
                    "--robots must be 1 to {MAX_FLEET_ROBOTS}, got {robots}"
                )));
            }
            if !(shift_s.is_finite() && shift_s > 0.0) {
                return Err(BenchError::Setup(format!(
                    "--shift-s must be more than 0 seconds (at most the shift's length), got {shift_s}"
                )));
            }
        }
        Ok(())
    }
}

/// The links cut and the roles behind each.
const LINKS: [(&str, &[&str]); 2] = [
    ("planners", &["planner-a", "planner-b"]),
    ("controller", &["controller-c"]),
];

/// The arguments that make a role a client of the router at `endpoint`, under `root`,
/// as `instance`.
pub fn client_args(endpoint: &str, root: &str, instance: &str) -> Vec<String> {
    [
        "--mode",
        "client",
        "--connect",
        endpoint,
        "--no-multicast",
        "--root",
        root,
        "--instance",
        instance,
    ]
    .iter()
    .map(|s| s.to_string())
    .collect()
}

async fn wait_port(addr: SocketAddr, limit: Duration) -> Result<(), BenchError> {
    let started = Instant::now();
    while tokio::net::TcpStream::connect(addr).await.is_err() {
        if started.elapsed() > limit {
            return Err(BenchError::Setup(format!(
                "nothing listens on {addr} after {limit:?}"
            )));
        }
        tokio::time::sleep(Duration::from_millis(50)).await;
    }
    Ok(())
}

/// Runs the chaos day.
pub async fn chaos(
    options: &ChaosOptions,
    progress: Progress<'_>,
) -> Result<ChaosReport, BenchError> {
    options.check()?;
    let started = Instant::now();
    let dir = tempfile::tempdir().map_err(setup)?;
    let root = format!("chaos-{}", std::process::id());
    let port = free_loopback_port().map_err(setup)?;
    let router_addr = SocketAddr::from(([127, 0, 0, 1], port));
    let router_endpoint = format!("tcp/127.0.0.1:{port}");
    let mut procs = Processes::new(&options.program, dir.path());
    procs.add(
        None,
        "router",
        ["router", "--listen", &router_endpoint, "--no-multicast"]
            .iter()
            .map(|s| s.to_string())
            .collect(),
    );
    procs.start("router")?;
    wait_port(router_addr, Duration::from_secs(20)).await?;

    let mut links = BTreeMap::new();
    for (name, _) in LINKS {
        links.insert(name, link::Link::start(router_addr).await.map_err(setup)?);
    }
    let stage = match options.site {
        ChaosSite::Day => site::day(dir.path(), options.rate)?,
        ChaosSite::Fleet { robots, shift_s } => {
            site::fleet(dir.path(), options.rate, robots, shift_s, options.seed)?
        }
    };
    for spec in &stage.roles {
        let endpoint = match spec.link.and_then(|l| links.get(l)) {
            Some(link) => link.endpoint(),
            None => router_endpoint.clone(),
        };
        let mut args = vec![spec.service.to_owned()];
        args.extend(client_args(&endpoint, &root, &spec.instance));
        args.extend(spec.extra.iter().cloned());
        procs.add(Some(spec.service), &spec.instance, args);
        procs.start(&spec.name())?;
    }

    let config = SessionArgs::client_of(&router_endpoint)
        .zenoh_config(None)
        .map_err(setup)?;
    let session = roam_runtime::session::open(config).await.map_err(setup)?;
    let watch = Watch::start(session, &root, &stage.watched).await?;
    let role_names: Vec<String> = stage.roles.iter().map(RoleSpec::name).collect();
    let answers: BTreeMap<String, (String, Answer)> = stage
        .roles
        .iter()
        .map(|s| {
            (
                s.name(),
                (watch.live_key(s.service, &s.instance), s.answer.clone()),
            )
        })
        .collect();
    for name in &role_names {
        let (key, _) = &answers[name];
        if watch.wait_live(key, true, PATIENCE).await.is_none() {
            return Err(BenchError::Setup(format!(
                "{name} never came up\n{}",
                procs.log_tails(20)
            )));
        }
    }

    // The scenario's robots the day does not run leave the sim before anyone moves.
    for robot in &stage.absent {
        watch
            .requester
            .request::<SimControl, SimStatus>(
                &keys::sim_control(&root),
                Some(&SimControl::RemoveRobot {
                    name: robot.clone(),
                }),
            )
            .await?;
    }

    let stop_marks = CancellationToken::new();
    let marks = tokio::spawn(marks::write_marks(
        watch.requester.clone(),
        root.clone(),
        MARK_EVERY,
        stop_marks.clone(),
    ));

    // The day ends with the last task of any robot.
    let last_start = stage
        .tasks
        .iter()
        .flat_map(|(_, tasks)| tasks.iter().map(|t| t.1))
        .fold(f64::NEG_INFINITY, f64::max);
    let day_end = stage
        .tasks
        .iter()
        .flat_map(|(_, tasks)| tasks.iter().map(|t| t.1 + t.2))
        .fold(f64::NEG_INFINITY, f64::max);
    if !day_end.is_finite() {
        return Err(BenchError::Setup("the day has no task".into()));
    }
    let all_reported = |reports: &[roam_proto::mission::WindowReport]| {
        stage.tasks.iter().all(|(robot, tasks)| {
            tasks.last().is_none_or(|(last, _, _)| {
                reports.iter().any(|r| &r.robot == robot && &r.task == last)
            })
        })
    };
    // Every role, but of the executives only the watched robot's: "an executive".
    let watched_executive = format!("mission-{}", stage.watched);
    let mut kill: Vec<&str> = vec!["router"];
    kill.extend(
        role_names
            .iter()
            .map(String::as_str)
            .filter(|n| !n.starts_with("mission-") || *n == watched_executive),
    );
    let partitions: Vec<&str> = LINKS.iter().map(|(l, _)| *l).collect();
    let spec = ScheduleSpec {
        kill: &kill,
        partitions: &partitions,
        freeze: &["planner-a"],
        from_sim_s: 10.0,
        to_sim_s: last_start - 15.0,
        restart_delay_s: RESTART_DELAY_S,
        partition_s: options.partition_s,
        freeze_s: options.freeze_s,
    };
    let day = schedule::schedule(&spec, options.seed);
    // The day's sim time at the rate, every hold, every recovery's patience, and room.
    let holds: f64 = day.iter().map(|s| s.hold_s).sum();
    let limit = Duration::from_secs_f64(day_end / options.rate + holds + 240.0);
    let out_of_time = |what: &str, procs: &Processes| {
        BenchError::Setup(format!(
            "the chaos day ran out of time ({limit:?}) {what}\n{}",
            procs.log_tails(20)
        ))
    };

    let mut faults = Vec::new();
    for (k, scheduled) in day.iter().enumerate() {
        progress(Done::of("faults", "faults", k, day.len()));
        loop {
            procs.restart_exited()?;
            if watch.sim_s().is_some_and(|t| t >= scheduled.at_sim_s) {
                break;
            }
            if started.elapsed() > limit {
                return Err(out_of_time(
                    &format!("waiting to {}", scheduled.fault.describe()),
                    &procs,
                ));
            }
            tokio::time::sleep(Duration::from_millis(100)).await;
        }
        let outcome = strike(
            &mut procs,
            &watch,
            &links,
            &answers,
            &role_names,
            scheduled,
            router_addr,
        )
        .await?;
        tracing::info!(fault = %outcome.what, sim_s = outcome.sim_from_s, "recovered");
        faults.push(outcome);
    }
    progress(Done::of("faults", "faults", day.len(), day.len()));

    // The rest of the day: until the last task is reported, or its window is long over.
    loop {
        procs.restart_exited()?;
        if all_reported(&watch.reports()) || watch.sim_s().is_some_and(|t| t > day_end + 30.0) {
            break;
        }
        if started.elapsed() > limit {
            return Err(out_of_time("waiting for the day's last report", &procs));
        }
        tokio::time::sleep(Duration::from_millis(200)).await;
    }
    stop_marks.cancel();
    let (mut marks_outcome, acked) = marks.await.map_err(setup)?;
    // The controller's statuses of the robot standing at its last task.
    tokio::time::sleep(Duration::from_secs(2)).await;
    marks_outcome.acked_lost = marks::lost(&watch.requester, &root, &acked).await;
    let (checked, out_of_step) =
        derived::out_of_step(&watch.requester, &root, stage.robot_radius_m).await;
    let states = watch.controller_states();
    let robots: Vec<&String> = stage.tasks.iter().map(|(robot, _)| robot).collect();
    let held = |s: &MissionState| {
        matches!(
            s,
            MissionState::HaltedPeb | MissionState::HaltedStale | MissionState::Stuck
        )
    };
    let reports = watch.reports();
    let windows = stage
        .tasks
        .iter()
        .flat_map(|(robot, tasks)| report::windows(robot, tasks, &reports, &faults))
        .collect();
    let mut report = ChaosReport {
        site: match options.site {
            ChaosSite::Day => "the built-in day".to_owned(),
            ChaosSite::Fleet { robots, shift_s } => {
                format!("the warehouse shift: {robots} robots, {shift_s} s")
            }
        },
        seed: options.seed,
        rate: options.rate,
        partition_s: options.partition_s,
        freeze_s: options.freeze_s,
        faults,
        windows,
        marks: marks_outcome,
        derived_layers_checked: checked,
        derived_layers_out_of_step: out_of_step,
        controller_states_at_end: robots
            .iter()
            .map(|r| {
                let state = states
                    .get(*r)
                    .map_or("none heard".to_owned(), |s| format!("{s:?}"));
                ((*r).clone(), state)
            })
            .collect(),
        robots_held_at_end: robots
            .iter()
            .filter(|r| states.get(**r).is_some_and(held))
            .count(),
        unplanned_restarts: procs
            .procs
            .iter()
            .filter(|p| p.unplanned_restarts > 0)
            .map(|p| (p.name.clone(), p.unplanned_restarts))
            .collect(),
        wall_s: started.elapsed().as_secs_f64(),
        goals: Vec::new(),
    };
    report.goals = report::goals(&report);
    Ok(report)
}

/// One fault: done, undone, and every role it touched watched until it answers again.
#[allow(clippy::too_many_arguments)]
async fn strike(
    procs: &mut Processes,
    watch: &Watch,
    links: &BTreeMap<&str, link::Link>,
    answers: &BTreeMap<String, (String, Answer)>,
    role_names: &[String],
    scheduled: &schedule::Scheduled,
    router_addr: SocketAddr,
) -> Result<FaultOutcome, BenchError> {
    let before = versions_within(watch, PATIENCE).await;
    let sim_from_s = watch.sim_s().unwrap_or(f64::NAN);
    let hold = Duration::from_secs_f64(scheduled.hold_s);
    let key_of = |role: &str| {
        answers
            .get(role)
            .map(|(key, _)| key.clone())
            .ok_or_else(|| BenchError::Setup(format!("no role {role}")))
    };
    let struck = Instant::now();
    let (touched, token_gone_s): (Vec<String>, Option<f64>) = match &scheduled.fault {
        Fault::Kill { role } if role == "router" => {
            procs.kill(role)?;
            tokio::time::sleep(hold).await;
            procs.start(role)?;
            wait_port(router_addr, PATIENCE).await?;
            (role_names.to_vec(), None)
        }
        Fault::Kill { role } => {
            let key = key_of(role)?;
            procs.kill(role)?;
            let gone = watch.wait_live(&key, false, PATIENCE).await;
            tokio::time::sleep(hold).await;
            procs.start(role)?;
            (vec![role.clone()], gone.map(|d| d.as_secs_f64()))
        }
        Fault::Partition { link } => {
            let cut = links
                .get(link.as_str())
                .ok_or_else(|| BenchError::Setup(format!("no link {link}")))?;
            let behind: Vec<String> = LINKS
                .iter()
                .find(|(l, _)| l == link)
                .map(|(_, roles)| roles.iter().map(|r| r.to_string()).collect())
                .unwrap_or_default();
            let keys = behind
                .iter()
                .map(|r| key_of(r))
                .collect::<Result<Vec<_>, _>>()?;
            cut.cut();
            let gone = hold_watching(watch, &keys, struck, hold).await;
            cut.heal();
            (behind, gone)
        }
        Fault::Freeze { role } => {
            let keys = vec![key_of(role)?];
            procs.freeze(role, true)?;
            let gone = hold_watching(watch, &keys, struck, hold).await;
            procs.freeze(role, false)?;
            (vec![role.clone()], gone)
        }
    };
    let since = Instant::now();
    let roles = recover(procs, watch, answers, &touched, since).await?;
    let after = versions_within(watch, PATIENCE).await;
    let layers_gone_back = match (&before, &after) {
        (Some(before), Some(after)) => watch::gone_back(before, after),
        _ => vec!["(the map server did not answer)".to_owned()],
    };
    Ok(FaultOutcome {
        what: scheduled.fault.describe(),
        fault: scheduled.fault.clone(),
        hold_s: scheduled.hold_s,
        token_gone_s,
        sim_from_s,
        sim_to_s: watch.sim_s().unwrap_or(f64::NAN),
        roles,
        layers_gone_back,
    })
}

/// Watches the `touched` roles at once until each holds its token and has answered.
async fn recover(
    procs: &mut Processes,
    watch: &Watch,
    answers: &BTreeMap<String, (String, Answer)>,
    touched: &[String],
    since: Instant,
) -> Result<Vec<RoleRecovery>, BenchError> {
    let mut roles: Vec<RoleRecovery> = touched
        .iter()
        .map(|role| RoleRecovery {
            role: role.clone(),
            live_again_s: None,
            first_answer_s: None,
        })
        .collect();
    while since.elapsed() < PATIENCE {
        procs.restart_exited()?;
        let mut pending = false;
        for r in &mut roles {
            let Some((key, answer)) = answers.get(&r.role) else {
                continue;
            };
            if r.live_again_s.is_none() && watch.is_live(key).await {
                r.live_again_s = Some(since.elapsed().as_secs_f64());
            }
            // An answer counts once the token is back: a role is not back before it is
            // live, whatever it published while it was not.
            if r.first_answer_s.is_none()
                && r.live_again_s.is_some()
                && watch.answers(answer, since).await
            {
                r.first_answer_s = Some(since.elapsed().as_secs_f64());
            }
            pending |= r.live_again_s.is_none() || r.first_answer_s.is_none();
        }
        if !pending {
            break;
        }
        tokio::time::sleep(Duration::from_millis(50)).await;
    }
    Ok(roles)
}

/// Waits out `hold` while watching `keys`' tokens: when the first of them went, in
/// seconds from `struck`; `None` if none did (a cut or a freeze shorter than Zenoh's
/// lease leaves the sessions up).
async fn hold_watching(
    watch: &Watch,
    keys: &[String],
    struck: Instant,
    hold: Duration,
) -> Option<f64> {
    let mut gone = None;
    while struck.elapsed() < hold {
        if gone.is_none() {
            for key in keys {
                if !watch.is_live(key).await {
                    gone = Some(struck.elapsed().as_secs_f64());
                    break;
                }
            }
        }
        let left = hold.saturating_sub(struck.elapsed());
        tokio::time::sleep(left.min(Duration::from_millis(200))).await;
    }
    gone
}

async fn versions_within(watch: &Watch, limit: Duration) -> Option<BTreeMap<String, u64>> {
    let started = Instant::now();
    while started.elapsed() < limit {
        if let Some(v) = watch.versions().await {
            return Some(v);
        }
        tokio::time::sleep(Duration::from_millis(100)).await;
    }
    None
}
