//! `roam demo`: the downtime day's report, with the driven path in the picture.

use super::*;

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
