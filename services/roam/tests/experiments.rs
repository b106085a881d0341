//! The `roam` binary's experiment and benchmark runners and the demo, run as a user runs
//! them: each prints its JSON, draws its pictures and shows progress on stderr.

use std::process::Command;

const ROAM: &str = env!("CARGO_BIN_EXE_roam");

/// Counts pixels of exactly `colour` on the map of a framed 800 x 800 px picture (the
/// built-in world at 8 px per cell), leaving out its legend, whose swatches have the
/// same colours.
fn count_colour(
    path: &std::path::Path,
    colour: [u8; 3],
    frame: &roam_world::legend::Frame,
) -> usize {
    let picture = image::open(path).expect("png").to_rgb8();
    let (left, top) = roam_world::legend::layout((800, 800), frame).picture;
    picture
        .enumerate_pixels()
        .filter(|(x, y, p)| {
            p.0 == colour && (left..left + 800).contains(x) && (top..top + 800).contains(y)
        })
        .count()
}

#[test]
fn reproduce_planner_prints_every_row_and_draws_each_model() {
    let out = tempfile::tempdir().expect("tmp");
    let output = Command::new(ROAM)
        .args([
            "reproduce",
            "planner",
            "--json",
            "--runs",
            "1",
            "--generations-per-t",
            "40",
            "--out",
        ])
        .arg(out.path())
        .output()
        .expect("run");
    assert!(
        output.status.success(),
        "{}",
        String::from_utf8_lossy(&output.stderr)
    );
    let value: serde_json::Value = serde_json::from_slice(&output.stdout).expect("json");
    let runs = value["initializations"]
        .as_array()
        .expect("initializations");
    let names: Vec<&str> = runs
        .iter()
        .filter_map(|r| r["initialization"].as_str())
        .collect();
    assert_eq!(names, ["roam", "paper"], "both by default, roam's first");
    let rows = runs[0]["rows"].as_array().expect("rows");
    assert_eq!(rows.len(), 2 * 3 * 3, "2 goals × 3 ratios × 3 models");
    for row in rows {
        for field in [
            "goal",
            "ratio",
            "model",
            "u_ges_median",
            "u_ges_mean",
            "d_median",
            "within_budget",
            "reached_goal",
        ] {
            assert!(!row[field].is_null(), "{field} missing in {row}");
        }
        assert!(row["u_ges_median"].as_f64().expect("number") > 0.0);
    }
    // Every verdict is one the rule computes; none is missing.
    for run in runs {
        let comparisons = run["comparisons"].as_array().expect("comparisons");
        assert_eq!(comparisons.len(), 7, "{run}");
        for c in comparisons {
            let verdict = c["verdict"].as_str().expect("verdict");
            assert!(
                ["holds", "near", "does_not_hold", "no_data"].contains(&verdict),
                "{c}"
            );
        }
    }
    // Side by side: each configuration under both, shares in 0..=1.
    let seeding = value["seeding"].as_array().expect("seeding");
    assert_eq!(seeding.len(), 18);
    for row in seeding {
        for init in ["roam", "paper"] {
            for share in ["within_budget", "reached_goal"] {
                let v = row[init][share].as_f64().expect("a share");
                assert!((0.0..=1.0).contains(&v), "{row}");
            }
        }
    }
    // Every model's picture has the same layout (two title lines, one legend).
    let frame = roam_experiments::reproduce::planner::picture_frame(
        roam_proto::planner::PlannerModel::Model1,
        roam_experiments::reproduce::planner::Initialization::Roam,
        40.0,
    );
    for model in ["model0", "model1", "model2"] {
        let png = out.path().join(format!("{model}.png"));
        assert!(
            count_colour(&png, roam_world::render::PATH.0, &frame) > 50,
            "{model}: the path is drawn"
        );
        assert!(
            count_colour(&png, roam_world::render::MARKER.0, &frame) > 50,
            "{model}: start and goal marked"
        );
    }
    for model in ["model0", "model1", "model2"] {
        let png = out.path().join(format!("paper-{model}.png"));
        assert!(png.exists(), "the paper's paths are drawn too");
    }
}

/// `--paper-init` plans with paper 000's own initialization only and says so.
#[test]
fn reproduce_planner_runs_the_papers_initialization_on_request() {
    let out = tempfile::tempdir().expect("tmp");
    let output = Command::new(ROAM)
        .args([
            "reproduce",
            "planner",
            "--json",
            "--paper-init",
            "--runs",
            "1",
            "--generations-per-t",
            "40",
            "--out",
        ])
        .arg(out.path())
        .output()
        .expect("run");
    assert!(
        output.status.success(),
        "{}",
        String::from_utf8_lossy(&output.stderr)
    );
    let value: serde_json::Value = serde_json::from_slice(&output.stdout).expect("json");
    let runs = value["initializations"]
        .as_array()
        .expect("initializations");
    assert_eq!(runs.len(), 1);
    assert_eq!(runs[0]["initialization"], "paper");
    assert_eq!(runs[0]["rows"].as_array().map(Vec::len), Some(18));
    assert_eq!(value["seeding"].as_array().map(Vec::len), Some(0));
}

/// An ES row's figures: its success share in 0..=1, and RMSE, steps and distance
/// positive numbers when some run succeeded, null when none did. (Checking only that
/// the keys exist passed with null, or with a string.)
fn check_figures(row: &serde_json::Value) {
    let share = row["success_rate"].as_f64().expect("a share");
    assert!((0.0..=1.0).contains(&share), "{row}");
    for field in ["rmse_m", "steps", "distance_m"] {
        match row[field].as_f64() {
            Some(v) => assert!(share > 0.0 && v > 0.0, "{field}: {row}"),
            None => assert!(share == 0.0 && row[field].is_null(), "{field}: {row}"),
        }
    }
}

#[test]
fn reproduce_apf_prints_every_scheme_and_draws_the_figures() {
    let out = tempfile::tempdir().expect("tmp");
    let (value, stderr) = run_json(
        &[
            "reproduce",
            "apf",
            "--json",
            "--es1-runs",
            "2",
            "--es2-runs",
            "1",
            "--es3-missions",
            "1",
            "--es3-runs",
            "1",
        ],
        Some(out.path()),
    );
    // ES1 with roam's PEB guard on and off, every scheme each, every failed run in one
    // class of cause.
    for (key, guard) in [("es1", true), ("es1_no_guard", false)] {
        let rows = value[key].as_array().expect(key);
        let schemes: Vec<&str> = rows.iter().filter_map(|r| r["scheme"].as_str()).collect();
        assert_eq!(
            schemes,
            ["plain", "fixed", "cutoff", "linear", "sinusoidal"],
            "{key}"
        );
        for row in rows {
            check_figures(row);
            assert_eq!(row["guard"].as_bool(), Some(guard), "{key}: {row}");
            let failures = row["failures"].as_u64().expect("a count");
            let c = &row["causes"];
            let classes: Option<Vec<u64>> = [
                "wrong_first_fix",
                "held_by_guard",
                "out_of_coverage",
                "estimate_diverged",
                "other",
            ]
            .iter()
            .map(|f| c[*f].as_u64())
            .collect();
            assert_eq!(classes.map(|v| v.iter().sum()), Some(failures), "{row}");
            if !guard {
                assert_eq!(c["held_by_guard"].as_u64(), Some(0), "{row}");
            }
        }
    }
    let es2 = value["es2"].as_array().expect("es2");
    assert_eq!(es2.len(), 4 * 10, "four IS schemes × z_is 0.0..0.9");
    for row in es2 {
        let z = row["z_is"].as_f64().expect("a z_is");
        assert!((0.0..=0.9 + 1e-9).contains(&z), "{row}");
        // On true positions every ES2 run completes: steps and distance are numbers.
        check_figures(row);
        assert_eq!(row["success_rate"].as_f64(), Some(1.0), "{row}");
    }
    let es3 = value["es3"].as_array().expect("es3");
    for row in es3 {
        check_figures(row);
        let compared = row["missions_compared"].as_u64().expect("a count");
        for field in ["rmse_change_pct", "steps_change_pct", "distance_change_pct"] {
            let finite = row[field].as_f64().is_some_and(f64::is_finite);
            assert!(finite || row[field].is_null(), "{field}: {row}");
        }
        assert_eq!(
            row["steps_change_pct"].as_f64().is_some(),
            compared > 0,
            "a change exactly where a mission was compared: {row}"
        );
    }
    for picture in [
        "es1_trajectories.png",
        "es2_trajectories.png",
        "es2_steps.png",
        "es2_distance.png",
    ] {
        let image = image::open(out.path().join(picture)).expect(picture);
        assert!(image.width() > 100 && image.height() > 100);
    }
    assert!(stderr.contains("es3: 5/5 runs"), "progress on stderr");
    // The claims: each a text, the paper's figure, ours and one of the four verdicts.
    // Plain APF's ES1 claim exists for both runs, and with the guard on its verdict
    // follows from its row (the paper: it fails).
    let claims = value["claims"].as_array().expect("claims");
    assert_eq!(claims.len(), 2 * 14 + 9 + 6);
    for c in claims {
        for f in ["claim", "paper", "ours"] {
            assert!(c[f].as_str().is_some_and(|t| !t.is_empty()), "{f}: {c}");
        }
        let verdict = c["verdict"].as_str().expect("a verdict");
        assert!(
            ["holds", "near", "does_not_hold", "no_data"].contains(&verdict),
            "{c}"
        );
    }
    // A single published value is printed as the paper has it, with ours as a multiple.
    let rmse = claims
        .iter()
        .find(|c| c["claim"] == "ES1 (guard on): fixed's mission RMSE, m")
        .expect("fixed's RMSE claim");
    assert_eq!(rmse["paper"], "0.21", "{rmse}");
    if rmse["verdict"] != "no_data" {
        assert!(rmse["ratios"][0].as_f64().is_some(), "{rmse}");
    }
    let plain_rate = value["es1"][0]["success_rate"].as_f64().expect("a share");
    let plain = claims
        .iter()
        .find(|c| c["claim"] == "ES1 (guard on): plain reaches B")
        .expect("plain's claim");
    let expected = if plain_rate >= 0.5 {
        "does_not_hold"
    } else {
        "holds"
    };
    assert_eq!(plain["verdict"], expected, "{plain}");
}

#[test]
fn reproduce_mapper_prints_the_four_modes_and_their_claims_and_draws_fig_3() {
    let out = tempfile::tempdir().expect("tmp");
    let (value, _) = run_json(
        &[
            "reproduce",
            "mapper",
            "--json",
            "--repetitions",
            "1",
            "--steps",
            "300",
        ],
        Some(out.path()),
    );
    let strategies = value["strategies"].as_array().expect("strategies");
    let names: Vec<&str> = strategies
        .iter()
        .filter_map(|s| s["name"].as_str())
        .collect();
    assert_eq!(names, ["curious", "recency", "poisson", "uniform"]);
    for s in strategies {
        assert!(s["rate_error_auc"].as_f64().expect("auc") > 0.0);
        let quality = s["final_map_quality"].as_f64().expect("quality");
        assert!((0.0..=1.0).contains(&quality));
    }
    // The claims, each judged from the figures above: the AUC ones must agree with
    // the strategies' AUCs.
    let claims = value["claims"].as_array().expect("claims");
    assert_eq!(claims.len(), 5, "{claims:?}");
    let auc = |i: usize| strategies[i]["rate_error_auc"].as_f64().expect("auc");
    for (claim, other) in [(0, 1), (1, 2), (4, 3)] {
        let c = &claims[claim];
        assert_eq!(
            c["paper"].as_str().map(|p| p.starts_with("yes")),
            Some(true)
        );
        let want = if auc(0) < auc(other) {
            "holds"
        } else {
            "does_not_hold"
        };
        assert_eq!(c["verdict"], want, "{c}");
    }
    for c in claims {
        assert!(c["claim"].is_string() && c["ours"].is_string(), "{c}");
    }
    let image = image::open(out.path().join("mapper_fig3.png")).expect("figure");
    assert!(image.width() > 100);
}

#[test]
fn bench_mapper_prints_updates_per_second() {
    let (value, _) = run_json(&["bench", "mapper", "--json", "--updates", "50"], None);
    assert_eq!(value["map_cells"], 1_000_000);
    assert!(value["updates_with_features_per_s"].as_f64().expect("rate") > 0.0);
}

#[test]
fn roam_demo_writes_the_report_with_the_driven_path_in_the_picture() {
    let out = tempfile::tempdir().expect("tmp");
    let output = Command::new(ROAM)
        .args(["demo", "--rate", "10", "--out"])
        .arg(out.path())
        .env("RUST_LOG", "warn")
        .output()
        .expect("run");
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert!(output.status.success(), "{stderr}");
    assert!(stderr.contains("window 1 -> goal1"), "progress: {stderr}");
    let report: serde_json::Value =
        serde_json::from_slice(&std::fs::read(out.path().join("report.json")).expect("json"))
            .expect("parses");
    for field in [
        "on_time",
        "information",
        "information_shortest_path",
        "information_baseline_plans",
        "peb_mean_m",
    ] {
        assert!(!report[field].is_null(), "{field} missing: {report}");
    }
    // One plan per window (the baseline) replayed for each window, within its window.
    let baseline = report["baseline_plans"].as_array().expect("baseline plans");
    assert_eq!(baseline.len(), 4, "{report}");
    for (w, t) in report["windows"]
        .as_array()
        .expect("windows")
        .iter()
        .zip(baseline)
    {
        let window =
            w["task_start_s"].as_f64().expect("start") - w["began_s"].as_f64().expect("began");
        // A window the robot began late can be shorter than the shortest path on
        // the baseline's slower time model: then the baseline's planner refuses, naming the floor.
        match t["refused"].as_str() {
            Some(reason) => {
                assert!(reason.contains("give at least"), "{t}");
                assert!(
                    t["t_eta_s"].is_null() && t["planned_information"] == 0.0,
                    "{t}"
                );
            }
            None => {
                let eta = t["t_eta_s"].as_f64().expect("baseline plan");
                assert!(
                    eta <= window + 1e-6,
                    "the baseline plan {t} does not fit window {w}"
                );
            }
        }
    }
    // The first window begins at the start of the day, never late: the baseline plans it.
    assert!(baseline[0]["refused"].is_null(), "{}", baseline[0]);
    // The day: four windows, one a round trip, each with the time model it planned with
    // and the share of the window the robot drove.
    let windows = report["windows"].as_array().expect("windows");
    assert_eq!(windows.len(), 4, "{report}");
    for w in windows {
        let share = w["time_model"]["driven_share"]
            .as_f64()
            .expect("driven share");
        // A late robot drove past the task's start: more than the window.
        let on_time = w["on_time"].as_bool().expect("on time");
        assert!(share >= 0.0 && (share <= 1.0 || !on_time), "{w}");
        assert!(
            w["time_model"]["v_lin"].as_f64().is_some_and(|v| v > 0.0),
            "{w}"
        );
    }
    let markdown = std::fs::read_to_string(out.path().join("report.md")).expect("md");
    assert!(markdown.contains("| 1 | goal1 |") && markdown.contains("world.png"));
    assert!(markdown.contains("one-plan baseline"), "{markdown}");

    // The built-in world: 100 x 100 cells of 0.2 m from (-10, -10), 8 px per cell,
    // framed with a title, a legend and a scale bar where the layout puts them.
    let picture = image::open(out.path().join("world.png"))
        .expect("png")
        .to_rgb8();
    let meta = roam_proto::map::GridMeta {
        width: 100,
        height: 100,
        resolution: 0.2,
        origin: roam_proto::map::Origin {
            x: -10.0,
            y: -10.0,
            ..Default::default()
        },
    };
    let frame = roam::demo_picture::frame(
        roam_mission::site::BUILTIN_DAY,
        0,
        10.0,
        windows.len(),
        &meta,
    );
    let layout = roam_world::legend::layout((800, 800), &frame);
    assert_eq!(picture.dimensions(), layout.size);
    let (left, top) = layout.picture;
    let pixel_at = |p: [f64; 2]| {
        let (x, y) = ((p[0] + 10.0) / 0.2, (p[1] + 10.0) / 0.2);
        (
            left + (x.floor() * 8.0 + 4.0) as u32,
            top + ((99.0 - y.floor()) * 8.0 + 4.0) as u32,
        )
    };
    let pixel = |p: [f64; 2]| {
        let (x, y) = pixel_at(p);
        *picture.get_pixel(x, y)
    };
    legend_and_title_are_drawn(&picture, &frame, &layout);
    let driven: Vec<[f64; 2]> =
        serde_json::from_value(report["driven_path"].clone()).expect("driven path");
    assert!(driven.len() > 50);
    // Away from the start and task places (and the window numbers up and right of
    // them), the driven path is red where it was driven.
    let markers = [[-8.0, -8.0], [-2.0, 4.0], [6.0, -7.0]];
    let away: Vec<[f64; 2]> = driven
        .iter()
        .copied()
        .filter(|p| {
            markers
                .iter()
                .all(|m| (p[0] - m[0]).hypot(p[1] - m[1]) > 2.0)
        })
        .collect();
    let red = away
        .iter()
        .filter(|p| pixel(**p) == image::Rgb(roam::demo_picture::DRIVEN.0))
        .count();
    assert!(
        red * 10 >= away.len() * 9,
        "{red} of {} driven points are red in the picture",
        away.len()
    );
    // The task places are marked green.
    assert_eq!(pixel([-2.0, 4.0]), image::Rgb([0, 170, 60]));
    // Window 1's number is up and to the right of the start: the labels' black ink
    // (nothing else on the map is pure black) within 60 px of it.
    let (sx, sy) = pixel_at(driven[0]);
    let ink_near_start = (sx..sx + 60)
        .flat_map(|x| (sy.saturating_sub(60)..sy).map(move |y| (x, y)))
        .filter(|&(x, y)| *picture.get_pixel(x, y) == image::Rgb([0, 0, 0]))
        .count();
    assert!(ink_near_start > 10, "window 1's number by the start");
    // 40 px per metre, a bar at most a quarter of the map's 800 px: 5 m.
    let bar = layout.scale_bar.expect("a scale bar");
    assert_eq!((bar.metres, bar.pixels), (5.0, 200));
    assert_eq!(
        *picture.get_pixel(bar.x + 100, bar.y + 1),
        image::Rgb([0, 0, 0])
    );
}

/// Every legend swatch of `frame` has its colour where `layout` puts it, and every
/// ink pixel of the title's letters is ink in `picture`.
fn legend_and_title_are_drawn(
    picture: &image::RgbImage,
    frame: &roam_world::legend::Frame,
    layout: &roam_world::legend::Layout,
) {
    assert!(!frame.legend.is_empty());
    for (entry, &(x, y, w, h)) in frame.legend.iter().zip(&layout.swatches) {
        let at = match entry.swatch {
            // A label's border is its colour; inside is paper and text.
            roam_world::legend::Swatch::Label(_) => (x, y),
            _ => (x + w / 2, y + h / 2),
        };
        assert_eq!(
            *picture.get_pixel(at.0, at.1),
            entry.colour,
            "legend: {}",
            entry.text
        );
    }
    let mut expected = image::RgbImage::from_pixel(
        picture.width(),
        picture.height(),
        image::Rgb([255, 255, 255]),
    );
    let ink = roam_world::legend::INK;
    for (line, &(x, y)) in frame.title.iter().zip(&layout.title) {
        roam_world::font::draw_text(
            &mut expected,
            i64::from(x),
            i64::from(y),
            line,
            roam_world::legend::TITLE_SCALE,
            ink,
        );
    }
    let letters: Vec<(u32, u32)> = expected
        .enumerate_pixels()
        .filter(|(_, _, p)| **p == ink)
        .map(|(x, y, _)| (x, y))
        .collect();
    assert!(letters.len() > 500, "a title of some length");
    let missing = letters
        .iter()
        .filter(|&&(x, y)| *picture.get_pixel(x, y) != ink)
        .count();
    assert_eq!(missing, 0, "title pixels missing: {:?}", frame.title);
}

#[test]
fn reproduce_mission_compares_the_couplings() {
    let (value, _) = run_json(
        &[
            "reproduce",
            "mission",
            "--json",
            "--missions",
            "1",
            "--generations",
            "50",
        ],
        None,
    );
    let variants: Vec<&str> = value["variants"]
        .as_array()
        .expect("variants")
        .iter()
        .filter_map(|v| v["variant"].as_str())
        .collect();
    assert_eq!(variants, ["static", "peb_cost", "change", "shortest"]);
    for v in value["variants"].as_array().expect("variants") {
        assert!(v["information"].as_f64().expect("information") > 0.0);
        let share = v["on_time_share"].as_f64().expect("share");
        assert!((0.0..=1.0).contains(&share));
        assert!(v["peb_mean_m"].as_f64().expect("peb") > 0.0);
    }
    // Every joining claim is judged, by the rule, from the figures above.
    let claims = value["claims"].as_array().expect("claims");
    assert_eq!(claims.len(), 5, "{claims:?}");
    for c in claims {
        let verdict = c["verdict"].as_str().expect("verdict");
        assert!(
            ["holds", "does_not_hold", "no_data"].contains(&verdict),
            "{c}"
        );
        assert!(!c["ours"].as_str().expect("ours").is_empty(), "{c}");
    }
    let on_time = value["variants"][0]["on_time_share"]
        .as_f64()
        .expect("share");
    let judged = claims
        .iter()
        .find(|c| {
            c["claim"]
                .as_str()
                .is_some_and(|t| t.contains("within its budget"))
        })
        .expect("the budget claim");
    assert_eq!(judged["verdict"] == "holds", on_time >= 1.0, "{judged}");
}

#[test]
fn reproduce_mission_days_reports_every_variant_window_and_goal_with_a_verdict() {
    let (value, stderr) = run_json(
        &[
            "reproduce",
            "mission",
            "--json",
            "--days",
            "2",
            "--generations",
            "20",
            "--jobs",
            "2",
        ],
        None,
    );
    assert_eq!(value["days"], 2);
    let variants: Vec<&str> = value["variants"]
        .as_array()
        .expect("variants")
        .iter()
        .filter_map(|v| v["variant"].as_str())
        .collect();
    assert_eq!(
        variants,
        ["plain", "executive", "no_change", "no_peb", "fastest_path"]
    );
    for v in value["variants"].as_array().expect("variants") {
        assert_eq!(v["days"], 2);
        assert_eq!(v["windows"], 8, "four windows a day: {v}");
        let share = v["share_median"].as_f64().expect("share");
        assert!((0.0..=1.0).contains(&share), "{share}");
        assert_eq!(v["by_window"].as_array().expect("by window").len(), 4);
    }
    // Every goal has a figure, a threshold and a verdict, and a shortfall exactly when
    // it does not hold.
    let goals = value["goals"].as_array().expect("goals");
    assert_eq!(goals.len(), 6);
    for g in goals {
        assert!(g["figure"].is_number(), "{g}");
        assert!(g["threshold"].is_number(), "{g}");
        let verdict = g["verdict"].as_str().expect("verdict");
        assert!(["holds", "does_not_hold"].contains(&verdict), "{g}");
        assert_eq!(
            g["shortfall"].is_string(),
            verdict == "does_not_hold",
            "{g}"
        );
    }
    let effects: Vec<&str> = value["effects"]
        .as_array()
        .expect("effects")
        .iter()
        .filter_map(|e| e["coupling"].as_str())
        .collect();
    assert_eq!(effects, ["change", "peb"]);
    assert_eq!(value["results"].as_array().expect("results").len(), 10);
    assert!(stderr.contains("2 days x 5 variants"), "{stderr}");
}

/// Runs `roam <args> [--out DIR]`, asserts it succeeded, and returns its stdout as JSON
/// with its stderr.
fn run_json(args: &[&str], out: Option<&std::path::Path>) -> (serde_json::Value, String) {
    let mut command = Command::new(ROAM);
    command.args(args);
    if let Some(dir) = out {
        command.arg("--out").arg(dir);
    }
    let output = command.output().expect("run");
    let stderr = String::from_utf8_lossy(&output.stderr).into_owned();
    assert!(output.status.success(), "{stderr}");
    let value = serde_json::from_slice(&output.stdout).expect("json");
    (value, stderr)
}

#[test]
fn bench_load_answers_or_refuses_every_request_and_none_hangs() {
    let (value, _) = run_json(&["bench", "load", "--json", "--requests", "30"], None);
    let count = |field: &str| value[field].as_u64().expect(field);
    assert_eq!(count("hung"), 0, "{value}");
    assert_eq!(count("failed"), 0, "{value}");
    assert_eq!(count("answered") + count("refused_busy"), 30, "{value}");
    assert!(
        count("answered") >= 2,
        "two planners answer at least one each: {value}"
    );
    assert!(value["peak_rss_mib"].as_f64().is_some());
}

#[test]
fn bench_fleet_closes_the_loop_for_every_robot() {
    let (value, _) = run_json(
        &[
            "bench",
            "fleet",
            "--json",
            "--robots",
            "4",
            "--seconds",
            "2",
        ],
        None,
    );
    let count = |field: &str| value[field].as_u64().expect(field);
    assert!(count("steps") >= 10, "{value}");
    // The loop is closed for every robot: commands answer most steps (a debug build
    // on a loaded machine may miss some of them).
    assert!(count("commands_expected") >= 4 * 10, "{value}");
    assert!(
        2 * count("commands_on_time") >= count("commands_expected"),
        "{value}"
    );
    assert!(
        count("commands_on_time") + count("commands_late") <= count("commands_expected"),
        "{value}"
    );
    assert!(value["cpu_share"].as_f64().is_some_and(|c| c > 0.0));
    assert!(value["rss_per_robot_mib"].as_f64().is_some());
}

/// `roam demo --fleet`, shortened: three robots of the warehouse's shift live through
/// Zenoh for its first 300 s (r1's first task is later, so it stays put), measured as the
/// batch measures a week: every window of the robots with tasks is reported, the
/// summary counts them and their lateness, the map is scored every sim minute, the
/// goals' verdicts follow from their figures, and the picture draws each robot that
/// drove. (Speed and lateness are the release build's, measured in the README, not here.)
#[test]
fn roam_demo_fleet_writes_the_fleets_report_and_pictures() {
    let out = tempfile::tempdir().expect("tmp");
    let output = Command::new(ROAM)
        .args([
            "demo",
            "--fleet",
            "--robots",
            "3",
            "--shift-s",
            "300",
            "--rate",
            "5",
            "--out",
        ])
        .arg(out.path())
        .env("RUST_LOG", "warn")
        .output()
        .expect("run");
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert!(output.status.success(), "{stderr}");
    let report: serde_json::Value =
        serde_json::from_slice(&std::fs::read(out.path().join("report.json")).expect("json"))
            .expect("parses");
    assert_eq!(report["robots"], 3, "{report}");
    let windows = report["windows"].as_array().expect("windows");
    // The shift's tasks that start within 300 s: r2's pick-1 (202.2 s), r3's (233.9 s).
    let tasks: Vec<(&str, &str)> = windows
        .iter()
        .map(|w| {
            (
                w["robot"].as_str().expect("robot"),
                w["task"].as_str().expect("task"),
            )
        })
        .collect();
    assert_eq!(tasks, [("r2", "pick-1"), ("r3", "pick-1")], "{report}");
    let summary = &report["summary"];
    assert_eq!(summary["variant"], "news");
    assert_eq!(summary["windows"], 2);
    let late = windows.iter().filter(|w| w["on_time"] == false).count();
    assert_eq!(summary["late"], late as u64, "{summary}");
    assert_eq!(report["on_time"], late == 0);
    // Map samples at 60, 120, ... s of the sim: a Brier score between 0 and 1.
    let brier = summary["brier"].as_f64().expect("the map was scored");
    assert!((0.0..=1.0).contains(&brier), "{summary}");
    // Beside the static map's, the reference a map that never looks gets.
    let never_looks = summary["brier_static"]
        .as_f64()
        .expect("the static map scored");
    assert!((0.0..=1.0).contains(&never_looks), "{summary}");
    // Each curious plan's answer time is counted (none may come back curious in a debug
    // build on a loaded machine: then there is no p99).
    let curious = summary["curious_plans"].as_u64().expect("plans");
    assert_eq!(summary["plan_p99_ms"].is_number(), curious > 0, "{summary}");
    for g in report["goals"].as_array().expect("goals") {
        let (figure, at_most) = (g["figure"].as_f64(), g["at_most"].as_f64().expect("bound"));
        assert_eq!(g["met"].as_bool(), figure.map(|f| f <= at_most), "{g}");
    }
    let svg = std::fs::read_to_string(out.path().join("warehouse-news.svg")).expect("svg");
    assert!(svg.contains("racks and walls") && svg.contains("UWB anchor"));
    assert!(
        svg.matches(r#"class="path""#).count() >= 2,
        "r2 and r3 drove"
    );
    assert!(out.path().join("detection.svg").exists());
    let markdown = std::fs::read_to_string(out.path().join("report.md")).expect("md");
    assert!(markdown.contains("| r2 | 1 | pick-1 |"), "{markdown}");
    assert!(markdown.contains("warehouse-news.svg"));
}
