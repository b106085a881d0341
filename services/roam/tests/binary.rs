//! The `roam` binary as a user runs it: a process that stops on SIGTERM within 2 s,
//! `roam stack --once` and its picture, `roam map inspect`.

use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

use roam_runtime::wait_for_liveliness;
use roam_runtime::SessionArgs;
use roam_stack::router::free_loopback_port;

const ROAM: &str = env!("CARGO_BIN_EXE_roam");

fn repo(path: &str) -> String {
    format!("{}/../../{path}", env!("CARGO_MANIFEST_DIR"))
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn a_map_server_process_stops_on_sigterm_within_two_seconds() {
    let port = free_loopback_port().expect("port");
    let endpoint = format!("tcp/127.0.0.1:{port}");
    let root = format!("sigterm-{}", std::process::id());
    let mut child = Command::new(ROAM)
        .args([
            "map-server",
            "--mode",
            "peer",
            "--no-multicast",
            "--listen",
            &endpoint,
            "--root",
            &root,
        ])
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .spawn()
        .expect("spawn roam");

    let client = roam_runtime::session::open(
        SessionArgs::client_of(&endpoint)
            .zenoh_config(None)
            .expect("config"),
    );
    // The server may not be listening yet: retry the client until it connects.
    let session = {
        let started = Instant::now();
        let mut opened = client.await;
        while opened.is_err() && started.elapsed() < Duration::from_secs(20) {
            tokio::time::sleep(Duration::from_millis(100)).await;
            opened = roam_runtime::session::open(
                SessionArgs::client_of(&endpoint)
                    .zenoh_config(None)
                    .expect("config"),
            )
            .await;
        }
        opened.expect("connect to the map server process")
    };
    wait_for_liveliness(
        &session,
        &format!("{root}/@live/map-server/*"),
        Duration::from_secs(20),
    )
    .await
    .expect("map server up");

    let started = Instant::now();
    let status = Command::new("kill")
        .args(["-TERM", &child.id().to_string()])
        .status()
        .expect("kill");
    assert!(status.success());
    let exit = loop {
        if let Some(exit) = child.try_wait().expect("wait") {
            break exit;
        }
        if started.elapsed() > Duration::from_secs(5) {
            let _ = child.kill();
            panic!("the map server did not stop within 5 s of SIGTERM");
        }
        tokio::time::sleep(Duration::from_millis(20)).await;
    };
    let took = started.elapsed();
    assert!(exit.success(), "exit status {exit:?}");
    assert!(took < Duration::from_secs(2), "stopping took {took:?}");
    let _ = session.close().await;
}

#[test]
fn stack_once_fetches_every_layer_and_draws_the_world() {
    let out = tempfile::tempdir().expect("tmp");
    let output = Command::new(ROAM)
        .args(["stack", "--once", "--out"])
        .arg(out.path())
        .env("ROAM_ROOT", format!("once-{}", std::process::id()))
        .output()
        .expect("run roam stack --once");
    let stdout = String::from_utf8_lossy(&output.stdout);
    assert!(
        output.status.success(),
        "{stdout}\n{}",
        String::from_utf8_lossy(&output.stderr)
    );
    for layer in ["occupancy", "inflated", "information", "heuristic"] {
        assert!(stdout.contains(layer), "{layer} missing from:\n{stdout}");
    }
    let report: serde_json::Value = serde_json::from_slice(
        &std::fs::read(out.path().join("report.json")).expect("report.json"),
    )
    .expect("json");
    // The four map layers, and the PEB layer once localization has sent it.
    let layers = report["layers"].as_array().expect("layers");
    assert!(layers.len() == 4 || layers.len() == 5, "{layers:?}");
    let missions = report["missions"].as_array().expect("missions");
    assert_eq!(missions.len(), 2, "start to goal1 and goal2");
    for mission in missions {
        assert_eq!(mission["curious_reaches_goal"], true, "{mission}");
        assert_eq!(mission["curious_within_budget"], true, "{mission}");
        assert!(
            mission["curious_information"].as_f64() > mission["shortest_information"].as_f64(),
            "{mission}"
        );
    }
    assert!(
        count_colour(
            &out.path().join("world.png"),
            roam_world::render::PATH.0,
            &roam::report::picture_frame("roam", 40.0)
        ) > 100,
        "planned paths drawn"
    );

    // The built-in world is 100 × 100 cells drawn at 8 px, framed with a title, a
    // legend and a scale bar: the border wall is dark, the lab (score 90, around
    // (-5, 8) m) is orange, open floor (score 5) near white.
    let picture = image::open(out.path().join("world.png"))
        .expect("png")
        .to_rgb8();
    let frame = roam::report::picture_frame("roam", 8.0 / 0.2);
    let layout = roam_world::legend::layout((800, 800), &frame);
    assert_eq!(picture.dimensions().1, layout.size.1);
    let (left, top) = layout.picture;
    let px = |x_m: f64, y_m: f64| {
        let (col, row) = (((x_m + 10.0) / 0.2) as u32, ((y_m + 10.0) / 0.2) as u32);
        *picture.get_pixel(left + col * 8 + 4, top + (99 - row) * 8 + 4)
    };
    for (entry, &(x, y, w, h)) in frame.legend.iter().zip(&layout.swatches) {
        assert_eq!(
            *picture.get_pixel(x + w / 2, y + h / 2),
            entry.colour,
            "{}",
            entry.text
        );
    }
    assert_eq!(px(-9.9, 0.0).0, [20, 20, 20], "border wall");
    let lab = px(-5.0, 8.0).0;
    assert!(lab[0] > 200 && lab[2] < 60, "lab tinted orange: {lab:?}");
    let floor = px(5.0, 5.0).0;
    assert!(
        floor.iter().all(|&c| c > 230),
        "floor near white: {floor:?}"
    );
}

#[test]
fn map_inspect_prints_nav2_counts_as_json() {
    let output = Command::new(ROAM)
        .args([
            "map",
            "inspect",
            &repo("config/maps/tb3_sandbox.yaml"),
            "--json",
        ])
        .output()
        .expect("run");
    assert!(output.status.success());
    let value: serde_json::Value = serde_json::from_slice(&output.stdout).expect("json");
    assert_eq!(
        value,
        serde_json::json!({"width": 384, "height": 384, "resolution": 0.05, "origin": [-10.0, -10.0, 0.0],
                           "occupied": 870, "free": 7903, "unknown": 138683})
    );
    let missing = Command::new(ROAM)
        .args(["map", "inspect", "/nonexistent/map.yaml"])
        .output()
        .expect("run");
    assert!(!missing.status.success());
    assert!(
        String::from_utf8_lossy(&missing.stderr).contains("/nonexistent/map.yaml does not exist")
    );
}

#[test]
fn help_reads_like_a_manual() {
    let output = Command::new(ROAM).arg("--help").output().expect("run");
    let text = String::from_utf8_lossy(&output.stdout);
    for needle in [
        "map-server",
        "router",
        "stack",
        "demo",
        "controller",
        "mapper",
        "mission",
        "ZENOH_CONFIG",
        "RUST_LOG",
        "ROAM_ROOT",
        "CONFIG FILE",
    ] {
        assert!(text.contains(needle), "--help lacks {needle}");
    }
}

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

/// A guard that stops a child process however the test ends.
struct Child(std::process::Child);

impl Drop for Child {
    fn drop(&mut self) {
        let _ = Command::new("kill")
            .args(["-TERM", &self.0.id().to_string()])
            .status();
        let started = Instant::now();
        while started.elapsed() < Duration::from_secs(5) {
            if let Ok(Some(_)) = self.0.try_wait() {
                return;
            }
            std::thread::sleep(Duration::from_millis(20));
        }
        let _ = self.0.kill();
        let _ = self.0.wait();
    }
}

#[test]
fn roam_plan_asks_a_running_stack_and_draws_the_path() {
    use std::io::{BufRead, BufReader};
    let port = free_loopback_port().expect("port");
    let endpoint = format!("tcp/127.0.0.1:{port}");
    let root = format!("plan-cli-{}", std::process::id());
    let mut child = Command::new(ROAM)
        .args(["stack", "--listen", &endpoint, "--root", &root])
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .expect("spawn stack");
    let stderr = child.stderr.take().expect("stderr");
    let stack = Child(child);
    // Wait for "roam stack up" (bounded), then keep draining stderr.
    let (tx, rx) = std::sync::mpsc::channel();
    std::thread::spawn(move || {
        for line in BufReader::new(stderr).lines().map_while(Result::ok) {
            if line.contains("roam stack up") {
                let _ = tx.send(());
            }
        }
    });
    rx.recv_timeout(Duration::from_secs(60))
        .expect("the stack comes up");

    let out = tempfile::tempdir().expect("tmp");
    let png = out.path().join("plan.png");
    let output = Command::new(ROAM)
        .args([
            "plan",
            "--mode",
            "client",
            "--connect",
            &endpoint,
            "--root",
            &root,
            "--start=-8,-8",
            "--goal=-2,4",
            "--budget",
            "60",
            "--generations",
            "50",
            "--json",
            "--png",
        ])
        .arg(&png)
        .output()
        .expect("run roam plan");
    assert!(
        output.status.success(),
        "{}",
        String::from_utf8_lossy(&output.stderr)
    );
    let text = String::from_utf8_lossy(&output.stdout);
    let json_end = text.rfind('}').expect("json");
    let plan: serde_json::Value = serde_json::from_str(&text[..=json_end]).expect("plan json");
    assert_eq!(plan["reaches_goal"], true);
    assert_eq!(plan["within_budget"], true);
    assert!(
        count_colour(
            &png,
            roam_world::render::PATH.0,
            &roam::pictures::plan_frame(vec![String::new(), String::new()], 40.0)
        ) > 50,
        "the path is drawn"
    );

    let refused = Command::new(ROAM)
        .args([
            "plan",
            "--mode",
            "client",
            "--connect",
            &endpoint,
            "--root",
            &root,
            "--start=-8,-8",
            "--goal=-2,4",
            "--budget",
            "5",
        ])
        .output()
        .expect("run roam plan");
    assert!(!refused.status.success());
    assert!(
        String::from_utf8_lossy(&refused.stderr).contains("shorter than the fastest path's ETA")
    );
    drop(stack);
}

/// Waits (bounded) until `roam map layers` through `endpoint` answers, and returns its
/// output.
fn layers_through(endpoint: &str, root: &str) -> serde_json::Value {
    let started = Instant::now();
    loop {
        let output = Command::new(ROAM)
            .args([
                "map",
                "layers",
                "--mode",
                "client",
                "--connect",
                endpoint,
                "--root",
                root,
                "--timeout",
                "2",
            ])
            .output()
            .expect("run roam map layers");
        if output.status.success() {
            return serde_json::from_slice(&output.stdout).expect("layer list json");
        }
        assert!(
            started.elapsed() < Duration::from_secs(60),
            "no answer: {}",
            String::from_utf8_lossy(&output.stderr)
        );
        std::thread::sleep(Duration::from_millis(200));
    }
}

/// deploy/README.md's recipe for running a service on another machine: a router, a map
/// server connected to it in client mode, and a client that asks through the router.
#[test]
fn a_router_process_connects_a_map_server_and_a_client() {
    let port = free_loopback_port().expect("port");
    let endpoint = format!("tcp/127.0.0.1:{port}");
    let root = format!("router-{}", std::process::id());
    let _router = Child(
        Command::new(ROAM)
            .args(["router", "--no-multicast", "--listen", &endpoint])
            .stdout(Stdio::null())
            .stderr(Stdio::null())
            .spawn()
            .expect("spawn router"),
    );
    let _map_server = Child(
        Command::new(ROAM)
            .args([
                "map-server",
                "--mode",
                "client",
                "--no-multicast",
                "--connect",
                &endpoint,
                "--root",
                &root,
                "--map",
                &repo("config/maps/depot.yaml"),
            ])
            .arg("--cfg")
            .arg("connect/timeout_ms:-1")
            .stdout(Stdio::null())
            .stderr(Stdio::null())
            .spawn()
            .expect("spawn map server"),
    );
    let list = layers_through(&endpoint, &root);
    let occupancy = list["layers"]
        .as_array()
        .expect("layers")
        .iter()
        .find(|l| l["name"] == "occupancy")
        .expect("occupancy layer")
        .clone();
    assert_eq!(occupancy["meta"]["width"], 604);
    assert_eq!(occupancy["version"], 1);
}

#[test]
fn every_shipped_scenario_renders_and_es1_shows_anchor_wall_and_robot() {
    let out = tempfile::tempdir().expect("tmp");
    for entry in std::fs::read_dir(repo("config/scenarios")).expect("scenarios") {
        let path = entry.expect("entry").path();
        if path.extension().and_then(|e| e.to_str()) != Some("yaml") {
            continue;
        }
        let png = out.path().join(format!(
            "{}.png",
            path.file_stem().and_then(|s| s.to_str()).unwrap_or("x")
        ));
        let status = Command::new(ROAM)
            .args(["sim", "render"])
            .arg(&path)
            .arg("--png")
            .arg(&png)
            .output()
            .expect("run");
        assert!(
            status.status.success(),
            "{}: {}",
            path.display(),
            String::from_utf8_lossy(&status.stderr)
        );
        assert!(png.exists());
    }
    // es1: 70 x 50 m at 0.5 m, drawn at 5 px per cell (800 / 140), north up, framed
    // with a title, a legend and a scale bar.
    let picture = image::open(out.path().join("es1.png"))
        .expect("png")
        .to_rgb8();
    let frame = roam::pictures::scenario_frame("es1", (70.0, 50.0), 0.5, 10.0);
    let layout = roam_world::legend::layout((700, 500), &frame);
    assert_eq!(picture.dimensions().1, layout.size.1);
    for (entry, &(x, y, w, h)) in frame.legend.iter().zip(&layout.swatches) {
        assert_eq!(
            *picture.get_pixel(x + w / 2, y + h / 2),
            entry.colour,
            "{}",
            entry.text
        );
    }
    let (left, top) = layout.picture;
    let px = |x: f64, y: f64| {
        *picture.get_pixel(
            left + (x / 0.5 * 5.0) as u32,
            top + ((50.0 - y) / 0.5 * 5.0) as u32,
        )
    };
    assert_eq!(px(4.0, 44.0), roam_sim::render::ANCHOR, "anchor a1");
    assert_eq!(px(10.0, 16.0), roam_sim::render::ROBOT, "the robot at A");
    assert_eq!(px(0.1, 25.0), roam_world::render::OCCUPIED, "the west wall");
}
