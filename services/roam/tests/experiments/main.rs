//! The `roam` binary's experiment and benchmark runners and the demo, run as a user runs
//! them: each prints its JSON, draws its pictures and shows progress on stderr. The
//! papers' reproductions here; the demo's day in `demo.rs`, the mission batches in
//! `mission.rs`, the fleet's in `fleet.rs`.

use std::process::Command;

mod demo;
mod fleet;
mod mission;

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
fn bench_arguments_out_of_their_limits_are_refused_naming_the_limit() {
    let cases: [(&[&str], &str); 6] = [
        (
            &["bench", "planner", "--anytime", "--checkpoints", ""],
            "invalid value '' for '--checkpoints",
        ),
        (
            &["bench", "planner", "--anytime", "--checkpoints", "30,10"],
            "checkpoints must increase: 30 ms then 10 ms",
        ),
        (
            &["bench", "planner", "--anytime", "--checkpoints", "0"],
            "checkpoint 0 ms is not in (0, 60000] ms",
        ),
        (
            &["bench", "fleet", "--robots", "0"],
            "--robots must be 1..=1000",
        ),
        (
            &["bench", "fleet", "--robots", "1001"],
            "--robots must be 1..=1000",
        ),
        (
            &["bench", "planner", "--replans", "--runs", "101"],
            "--runs 101: give 1 to 100 (MAX_DAYS) days",
        ),
    ];
    for (args, expected) in cases {
        let output = Command::new(ROAM).args(args).output().expect("run");
        let stderr = String::from_utf8_lossy(&output.stderr);
        assert!(!output.status.success(), "{args:?} ran");
        assert!(stderr.contains(expected), "{args:?}: {stderr}");
    }
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
