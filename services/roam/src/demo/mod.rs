//! `roam demo`: roam's main job on its embedded default. The whole stack boots in one
//! process on the demo's day world (`config/scenarios/day.yaml`, embedded: a moving
//! cart, 3 m observations, a poorly covered north-east room), the sim runs faster than
//! real time, and one robot spends the downtime before each of its four tasks (one a
//! round trip) on a curious path: the mission executive plans it (paper 000) with the
//! robot's own time model and the PEB cost, the controller drives it on the
//! localization's estimates (paper 002), and the run ends with a report directory.
mod drive;
mod error;
mod options;
mod report;
mod view;

use std::time::{Duration, Instant};

use roam_stack::stack::{Stack, StackOptions};

use drive::drive;
pub(crate) use error::write_error;
pub use error::DemoError;
pub use options::{indoor_apf, DemoOptions, LiveView, DEMO_W_LOC};
pub use report::DemoReport;
pub(crate) use view::with_live_view;

/// Runs the demo and writes `world.png`, `report.json` and `report.md` to the out dir.
pub async fn run(
    options: &DemoOptions,
    progress: &(dyn Fn(&str) + Sync),
) -> Result<DemoReport, DemoError> {
    let started = Instant::now();
    std::fs::create_dir_all(&options.out_dir).map_err(|e| write_error(&options.out_dir, e))?;
    // The day's world goes to every service as a file in the report directory, so the
    // report holds the world it was made on.
    let world = options.out_dir.join("world.yaml");
    std::fs::write(&world, &options.site.scenario_yaml).map_err(|e| write_error(&world, e))?;
    for warning in &options.site.warnings {
        progress(&format!("warning: {warning}"));
    }
    progress("booting the stack (map server, planner, sim, localization, controller, mapper)");
    let stack = Stack::start(
        StackOptions {
            root: options.root.clone(),
            map: Some(world.clone()),
            planners: 1,
            sim_rate: Some(options.rate),
            apf: Some(indoor_apf()),
            ros2: options.ros2.clone(),
            listen: options.listen.clone(),
            ..StackOptions::default()
        },
        Duration::from_secs(30),
    )
    .await?;
    if options.listen.is_some() || options.ros2.is_some() {
        progress(&format!(
            "router {} (root '{}'); connect with --connect {}",
            stack.router.endpoint, stack.root, stack.router.endpoint
        ));
    }
    with_live_view(stack, &options.view, progress, async |stack| {
        drive(stack, options, &world, progress, started).await
    })
    .await
}
