//! `roam plan`: ask a running planner for a path, and draw it.

use std::path::PathBuf;

use anyhow::{bail, Context};
use clap::Args;
use roam_planner::client::{PlanTicket, PlannerClient};
use roam_proto::cells::Cells;
use roam_proto::keys;
use roam_proto::map::Layer;
use roam_proto::planner::{GaOverrides, Plan, PlanRequest, PlannerModel, ShortestPathUse};
use roam_runtime::Requester;
use roam_world::grid::Grid;
use roam_world::render;

use super::client::{connect, ClientArgs};

#[derive(Debug, Args)]
pub(crate) struct PlanArgs {
    /// Start, world metres: X,Y.
    #[arg(long, value_parser = parse_point, allow_hyphen_values = true)]
    start: [f64; 2],
    /// Goal, world metres: X,Y.
    #[arg(long, value_parser = parse_point, allow_hyphen_values = true)]
    goal: [f64; 2],
    /// Seconds the robot has to drive (t_exec).
    #[arg(long)]
    budget: f64,
    /// Curiosity model: 0, 1, 2, greedy (not a GA: via-points by information per
    /// second) or shortest (the fastest path).
    #[arg(long, default_value = "1", value_parser = parse_model)]
    model: PlannerModel,
    /// Seconds the planner may take (t_plan).
    #[arg(long, default_value_t = 5.0)]
    deadline: f64,
    #[arg(long, default_value_t = 0)]
    seed: u64,
    /// GA generations (Table I: 2000).
    #[arg(long)]
    generations: Option<u32>,
    /// Draw the map, the information layer and the path to this PNG.
    #[arg(long, value_name = "FILE")]
    png: Option<PathBuf>,
    /// Print the whole plan as JSON.
    #[arg(long)]
    json: bool,
    #[command(flatten)]
    client: ClientArgs,
}

pub(crate) fn parse_point(text: &str) -> Result<[f64; 2], String> {
    let (x, y) = text
        .split_once(',')
        .ok_or_else(|| format!("'{text}' is not X,Y (e.g. -8,-8)"))?;
    let parse = |v: &str| {
        v.trim()
            .parse::<f64>()
            .map_err(|e| format!("'{v}' in '{text}': {e}"))
    };
    Ok([parse(x)?, parse(y)?])
}

pub(crate) fn parse_model(text: &str) -> Result<PlannerModel, String> {
    match text {
        "0" | "model0" => Ok(PlannerModel::Model0),
        "1" | "model1" => Ok(PlannerModel::Model1),
        "2" | "model2" => Ok(PlannerModel::Model2),
        "shortest" => Ok(PlannerModel::Shortest),
        "greedy" => Ok(PlannerModel::Greedy),
        "anytime" => Ok(PlannerModel::Anytime),
        other => Err(format!(
            "'{other}' is not a model; use 0, 1, 2, greedy, anytime or shortest"
        )),
    }
}

pub(crate) async fn plan(args: PlanArgs) -> anyhow::Result<()> {
    let (requester, session) = connect(&args.client).await?;
    let planner = PlannerClient::new(session.clone(), &args.client.root);
    let mut request = PlanRequest {
        request_id: None,
        cancel_token: None,
        start: args.start,
        goal: args.goal,
        t_exec_s: args.budget,
        deadline_s: args.deadline,
        model: args.model,
        params: GaOverrides {
            max_generations: args.generations,
            ..GaOverrides::default()
        },
        seed: args.seed,
        map_version: None,
        shortest: ShortestPathUse::Omit,
        seed_route: Vec::new(),
    };
    // A fresh random id and cancel token for this request: Ctrl-C cancels the plan with
    // the token, and the planner replies with its best path so far.
    let ticket = PlanTicket::issue(&mut request);
    let pending = planner.plan(&request);
    tokio::pin!(pending);
    let outcome = tokio::select! {
        outcome = &mut pending => outcome,
        _ = tokio::signal::ctrl_c() => {
            eprintln!("cancelling plan {}; waiting for its best path so far", ticket.request_id);
            planner.cancel(&ticket).await?;
            pending.await
        }
    };
    let picture = match (&outcome, &args.png) {
        (Ok(plan), Some(path)) => Some(draw_plan(&requester, &args.client.root, plan, path).await),
        _ => None,
    };
    let _ = session.close().await;
    let plan = outcome?;
    if let Some(result) = picture {
        result?;
    }
    if args.json {
        println!("{}", serde_json::to_string_pretty(&plan)?);
    } else {
        println!(
            "{} plan {} by {}: {} cells, ETA {:.1} s of {:.1} s ({}), {} the goal\n  U_ges {:.0}, D {:.1}, distinct information {:.0}, fitness {:.0}, {} generations in {:.0} ms ({:?})",
            plan.model.as_str(),
            plan.request_id,
            plan.instance,
            plan.cells.len(),
            plan.t_eta_s,
            args.budget,
            if plan.within_budget { "within budget" } else { "OVER budget" },
            if plan.reaches_goal { "reaches" } else { "does NOT reach" },
            plan.u_ges,
            plan.density,
            plan.distinct_information,
            plan.fitness.total,
            plan.generations,
            plan.planning_ms,
            plan.stop_reason
        );
    }
    if let Some(path) = &args.png {
        println!("picture: {}", path.display());
    }
    Ok(())
}

/// Fetches occupancy and information from the map server and draws the plan over them.
pub(crate) async fn draw_plan(
    requester: &Requester,
    root: &str,
    plan: &Plan,
    path: &std::path::Path,
) -> anyhow::Result<()> {
    let occupancy: Layer = requester
        .request::<Layer, Layer>(&keys::map_layer(root, "occupancy"), None)
        .await?;
    let information: Layer = requester
        .request::<Layer, Layer>(&keys::map_layer(root, "information"), None)
        .await?;
    let (Cells::I8(occ), Cells::U8(info)) = (occupancy.cells, information.cells) else {
        bail!("the map server's occupancy or information layer has an unexpected type");
    };
    let occ = Grid {
        meta: occupancy.meta,
        cells: occ,
    };
    let info = Grid {
        meta: information.meta,
        cells: info,
    };
    let scale = (800 / occ.meta.width.max(occ.meta.height)).clamp(1, 8);
    let mut image = render::render_map(&occ, Some(&info), scale);
    render::draw_path(
        &mut image,
        occ.meta.height,
        &plan.cells,
        scale,
        render::PATH,
    );
    for end in [plan.cells.first(), plan.cells.last()]
        .into_iter()
        .flatten()
    {
        render::draw_marker(&mut image, occ.meta.height, *end, scale, render::MARKER);
    }
    let title = vec![
        format!(
            "roam plan: {}, ETA {:.1} s, {} the goal",
            plan.model.as_str(),
            plan.t_eta_s,
            if plan.reaches_goal {
                "reaches"
            } else {
                "misses"
            }
        ),
        format!(
            "distinct information {:.0}, {} generations",
            plan.distinct_information, plan.generations
        ),
    ];
    let frame = roam::pictures::plan_frame(title, f64::from(scale) / occ.meta.resolution);
    roam_world::legend::framed(&image, &frame)
        .save(path)
        .with_context(|| format!("writing {}", path.display()))?;
    Ok(())
}
