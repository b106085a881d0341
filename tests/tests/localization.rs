//! Localization through Zenoh with the sim world: ranges in, estimates out at the sim's
//! rate; a PEB field query on ES1 and its picture; the PEB layer in the map server.

use roam_proto::cells::Cells;
use roam_proto::localization::{PebQuery, PebReply, PebWhere, PositionEstimate};
use roam_proto::map::{GridMeta, Layer, Origin};
use roam_proto::sim::{GroundTruth, RangeScan, SimControl, SimStatus};
use roam_proto::{decode, encode, keys, ErrorCode};
use roam_runtime::ClientError;
use roam_tests::{repo_path, within, Harness};

#[tokio::test(flavor = "multi_thread", worker_threads = 4)]
async fn ranges_in_estimates_out_at_the_sim_rate() {
    let harness = Harness::start().await;
    let sim = harness
        .start_role(harness.sim_config(Some("config/scenarios/es1.yaml")))
        .await;
    let localization = harness
        .start_role(harness.localization_config(Some("config/scenarios/es1.yaml")))
        .await;
    let client = harness.client().await;
    let root = harness.root.clone();
    let estimates = within(
        "subscribe",
        client
            .session()
            .declare_subscriber(keys::robot_estimate(&root, "robot")),
    )
    .await
    .expect("sub");
    let truth = within(
        "subscribe",
        client
            .session()
            .declare_subscriber(keys::robot_truth(&root, "robot")),
    )
    .await
    .expect("sub");
    let steps = 10;
    let _: SimStatus = within(
        "step",
        client.request(
            &keys::sim_control(&root),
            Some(&SimControl::Step { n: steps }),
        ),
    )
    .await
    .expect("step");
    for step in 1..=u64::from(steps) {
        let e: PositionEstimate = decode(
            &within("estimate", estimates.recv_async())
                .await
                .expect("sample")
                .payload()
                .to_bytes(),
        )
        .expect("estimate");
        let t: GroundTruth = decode(
            &within("truth", truth.recv_async())
                .await
                .expect("sample")
                .payload()
                .to_bytes(),
        )
        .expect("truth");
        assert_eq!(
            (e.step, t.step),
            (step, step),
            "one estimate per scan, in order"
        );
        assert!(!e.degraded, "waypoint A is covered by three anchors");
        let peb = e.peb_m.expect("finite PEB");
        let error = (e.position[0] - t.at[0]).hypot(e.position[1] - t.at[1]);
        assert!(
            error < 5.0 * peb + 0.05,
            "error {error} m against PEB {peb} m"
        );
        assert!(e.anchors_used.len() >= 3);
    }
    localization.stop().await.1.expect("clean stop");
    sim.stop().await.1.expect("clean stop");
    harness.close().await;
}

/// A scan's time is checked against the sim clock as the mapper checks an
/// observation's: one stamped far ahead of the clock (a forged 1e300, or 1000 s on)
/// gives no estimate, and the next scan on the clock does.
#[tokio::test(flavor = "multi_thread", worker_threads = 4)]
async fn a_scan_stamped_ahead_of_the_sim_clock_gives_no_estimate() {
    let harness = Harness::start().await;
    let sim = harness
        .start_role(harness.sim_config(Some("config/scenarios/es1.yaml")))
        .await;
    let localization = harness
        .start_role(harness.localization_config(Some("config/scenarios/es1.yaml")))
        .await;
    let client = harness.client().await;
    let root = harness.root.clone();
    let subscribe = |key: String| within("subscribe", client.session().declare_subscriber(key));
    let estimates = subscribe(keys::robot_estimate(&root, "robot"))
        .await
        .expect("sub");
    let scans = subscribe(keys::robot_ranges(&root, "robot"))
        .await
        .expect("sub");
    let status: SimStatus = within(
        "step",
        client.request(&keys::sim_control(&root), Some(&SimControl::Step { n: 3 })),
    )
    .await
    .expect("step");
    let mut last: Option<RangeScan> = None;
    for _ in 0..3 {
        let sample = within("scan", scans.recv_async()).await.expect("sample");
        last = Some(decode(&sample.payload().to_bytes()).expect("scan"));
        within("estimate", estimates.recv_async())
            .await
            .expect("estimate");
    }
    let last = last.expect("a scan");
    for (step, time_s) in [(100, status.time_s + 1000.0), (101, 1e300)] {
        let forged = RangeScan {
            step,
            time_s,
            ..last.clone()
        };
        within(
            "put",
            client
                .session()
                .put(keys::robot_ranges(&root, "robot"), encode(&forged)),
        )
        .await
        .expect("put");
    }
    let on_clock = RangeScan {
        step: 102,
        ..last.clone()
    };
    within(
        "put",
        client
            .session()
            .put(keys::robot_ranges(&root, "robot"), encode(&on_clock)),
    )
    .await
    .expect("put");
    let e: PositionEstimate = decode(
        &within("estimate", estimates.recv_async())
            .await
            .expect("sample")
            .payload()
            .to_bytes(),
    )
    .expect("estimate");
    assert_eq!(e.step, 102, "the scans ahead of the clock gave no estimate");
    assert_eq!(e.time_s, last.time_s);
    localization.stop().await.1.expect("clean stop");
    sim.stop().await.1.expect("clean stop");
    harness.close().await;
}

#[tokio::test(flavor = "multi_thread", worker_threads = 4)]
async fn a_peb_field_on_es1_shows_the_well_covered_area() {
    let harness = Harness::start().await;
    // The map server on the same world as localization: a stack runs one world.
    let map_server = harness
        .start_role(roam_map_server::MapServerConfig {
            map: Some(repo_path("config/scenarios/es1.yaml")),
            ..harness.map_server_config()
        })
        .await;
    let localization = harness
        .start_role(harness.localization_config(Some("config/scenarios/es1.yaml")))
        .await;
    let client = harness.client().await;
    let root = harness.root.clone();
    // ES1 is 70 x 50 m: a 1 m field over it.
    let meta = GridMeta {
        width: 70,
        height: 50,
        resolution: 1.0,
        origin: Origin::default(),
    };
    let query = PebQuery {
        at: PebWhere::Region(meta),
        anchors: None,
        gradient: false,
        crb: false,
    };
    let reply: PebReply = within(
        "peb field",
        client.request(&keys::localization_peb(&root), Some(&query)),
    )
    .await
    .expect("field");
    let PebReply::Field {
        cells: Cells::F32(peb),
        ..
    } = reply
    else {
        panic!("a field")
    };
    assert_eq!(peb.len(), 70 * 50);
    let at = |x: usize, y: usize| peb[y * 70 + x];
    assert!(
        at(10, 16) < 1.0,
        "waypoint A is well covered: {}",
        at(10, 16)
    );
    let uncovered = peb.iter().filter(|v| v.is_infinite()).count();
    assert!(
        uncovered > 0 && uncovered < peb.len(),
        "ES1 is sparse: {uncovered} uncovered cells"
    );

    // The CRB over a small region around A: PEB² is its trace.
    let small = GridMeta {
        width: 4,
        height: 3,
        resolution: 1.0,
        origin: Origin {
            x: 8.0,
            y: 15.0,
            yaw: 0.0,
        },
    };
    let crb_query = PebQuery {
        at: PebWhere::Region(small),
        anchors: None,
        gradient: false,
        crb: true,
    };
    let reply: PebReply = within(
        "crb field",
        client.request(&keys::localization_peb(&root), Some(&crb_query)),
    )
    .await
    .expect("crb field");
    let PebReply::Field {
        cells: Cells::F32(small_peb),
        crb: Some(crb),
        ..
    } = reply
    else {
        panic!("a field with the CRB")
    };
    let (Cells::F32(xx), Cells::F32(yy)) = (crb.xx, crb.yy) else {
        panic!("f32 CRB cells")
    };
    let mut compared = 0;
    for i in 0..12 {
        let trace = xx[i] + yy[i];
        // No fix (fewer than three anchors in range): unbounded both ways.
        if small_peb[i].is_infinite() {
            assert!(trace.is_infinite(), "cell {i}: PEB inf vs tr CRB {trace}");
            continue;
        }
        compared += 1;
        assert!(
            (small_peb[i] * small_peb[i] - trace).abs() <= 1e-4 * trace.max(1e-6),
            "cell {i}: PEB² {} vs tr CRB {trace}",
            small_peb[i] * small_peb[i]
        );
    }
    assert!(compared > 0, "no bounded cell in the region to compare");

    // The picture: covered cells are coloured by PEB, uncovered ones grey.
    let out = tempfile::tempdir().expect("tmp");
    let png = out.path().join("peb.png");
    roam::peb_picture::render(&meta, &peb, 4)
        .save(&png)
        .expect("save");
    let picture = image::open(&png).expect("png").to_rgb8();
    let pixel = |x: usize, y: usize| *picture.get_pixel(x as u32 * 4 + 2, (49 - y) as u32 * 4 + 2);
    assert_eq!(
        pixel(10, 16),
        roam::peb_picture::colour(at(10, 16)),
        "A drawn by its PEB"
    );
    let (ux, uy) = (0..70 * 50)
        .find(|&i| peb[i].is_infinite())
        .map(|i| (i % 70, i / 70))
        .expect("an uncovered cell");
    assert_eq!(pixel(ux, uy), roam::peb_picture::UNCOVERED);

    // Points with the gradient, and a refusal.
    let points = PebQuery {
        at: PebWhere::Points(vec![[10.0, 16.0], [35.0, 28.0]]),
        anchors: None,
        gradient: true,
        crb: false,
    };
    let PebReply::Points(values) = within(
        "points",
        client.request::<PebQuery, PebReply>(&keys::localization_peb(&root), Some(&points)),
    )
    .await
    .expect("points") else {
        panic!("points")
    };
    assert!(values
        .iter()
        .all(|v| v.peb_m.is_some() && v.crb.is_some() && v.gradient.is_some()));
    let bad = PebQuery {
        at: PebWhere::Points(vec![[f64::NAN, 0.0]]),
        anchors: None,
        gradient: false,
        crb: false,
    };
    match within(
        "bad",
        client.request::<PebQuery, PebReply>(&keys::localization_peb(&root), Some(&bad)),
    )
    .await
    {
        Err(ClientError::Refused(r)) => assert!(
            matches!(r.code, ErrorCode::InvalidRequest | ErrorCode::Malformed),
            "{r}"
        ),
        other => panic!("{other:?}"),
    }

    // The PEB layer arrives in the map server.
    let layer = loop {
        match within(
            "peb layer",
            client.request::<Layer, Layer>(&keys::map_layer(&root, "peb"), None),
        )
        .await
        {
            Ok(layer) => break layer,
            Err(_) => tokio::time::sleep(std::time::Duration::from_millis(50)).await,
        }
    };
    assert_eq!(
        (layer.meta.width, layer.meta.height),
        (140, 100),
        "over ES1's 0.5 m map"
    );
    localization.stop().await.1.expect("clean stop");
    map_server.stop().await.1.expect("clean stop");
    harness.close().await;
}
