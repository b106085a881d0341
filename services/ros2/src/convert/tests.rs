use super::*;

fn layer(cells: Cells, width: u32, height: u32) -> Layer {
    Layer {
        name: "x".into(),
        version: 1,
        meta: GridMeta {
            width,
            height,
            resolution: 0.2,
            origin: Origin {
                x: -10.0,
                y: -5.0,
                yaw: 0.0,
            },
        },
        derived_from: None,
        cells,
    }
}

#[test]
fn layers_become_grids_cell_for_cell() {
    let occupancy = layer(Cells::I8(vec![-1, 0, 100, 50, 0, 0]), 3, 2);
    let grid = layer_to_grid(&occupancy, Scale::Occupancy, Time::default()).expect("grid");
    assert_eq!(grid.data, [-1, 0, 100, 50, 0, 0]);
    assert_eq!((grid.info.width, grid.info.height), (3, 2));
    assert_eq!(grid.info.resolution, 0.2);
    assert_eq!(grid.info.origin.position.x, -10.0);
    assert_eq!(grid.header.frame_id, "map");
    let info = layer(Cells::U8(vec![0, 5, 100, 255]), 2, 2);
    assert_eq!(
        layer_to_grid(&info, Scale::Score, Time::default())
            .expect("grid")
            .data,
        [0, 5, 100, 100]
    );
    let p = layer(Cells::F32(vec![0.0, 0.254, 1.0, f32::NAN]), 2, 2);
    assert_eq!(
        layer_to_grid(&p, Scale::Probability, Time::default())
            .expect("grid")
            .data,
        [0, 25, 100, -1]
    );
    let peb = layer(Cells::F32(vec![0.05, 0.5, 2.0, f32::INFINITY]), 2, 2);
    let scale = Scale::Metres { full_m: 1.0 };
    assert_eq!(
        layer_to_grid(&peb, scale, Time::default())
            .expect("grid")
            .data,
        [5, 50, 100, 100]
    );
    let short = layer(Cells::I8(vec![0; 5]), 3, 2);
    assert!(layer_to_grid(&short, Scale::Occupancy, Time::default()).is_err());
}

#[test]
fn a_ros_map_becomes_occupancy_and_bad_ones_are_refused() {
    let occupancy = layer(Cells::I8(vec![-1, 0, 100, 50, 0, 0]), 3, 2);
    let grid = layer_to_grid(&occupancy, Scale::Occupancy, Time::default()).expect("grid");
    let (meta, cells) = grid_to_occupancy(&grid, 100).expect("back");
    assert_eq!(cells, occupancy.cells);
    assert_eq!(meta.width, 3);
    assert!((meta.resolution - 0.2).abs() < 1e-6);
    // 10⁹ cells, refused from the header alone, naming the limit.
    let mut huge = grid.clone();
    huge.info.width = 40_000;
    huge.info.height = 25_000;
    let refused = grid_to_occupancy(&huge, 16_777_216).expect_err("huge");
    assert!(refused.to_string().contains("max_layer_cells"), "{refused}");
    assert!(refused.to_string().contains("1000000000"), "{refused}");
    let mut nan = grid.clone();
    nan.info.resolution = f32::NAN;
    assert!(grid_to_occupancy(&nan, 100).is_err());
    let mut odd = grid.clone();
    odd.data[0] = 101;
    assert!(grid_to_occupancy(&odd, 100).is_err());
    let mut short = grid;
    short.data.pop();
    assert!(grid_to_occupancy(&short, 100).is_err());
}

#[test]
fn paths_face_their_next_point() {
    let p = path(&[[0.0, 0.0], [1.0, 0.0], [1.0, 1.0]], Time::default());
    assert_eq!(p.poses.len(), 3);
    assert!(p.poses[0].pose.orientation.yaw().abs() < 1e-12);
    let up = std::f64::consts::FRAC_PI_2;
    assert!((p.poses[1].pose.orientation.yaw() - up).abs() < 1e-12);
    assert!((p.poses[2].pose.orientation.yaw() - up).abs() < 1e-12);
}

#[test]
fn the_crb_is_the_covariance() {
    let estimate = PositionEstimate {
        robot: "r1".into(),
        step: 1,
        time_s: 0.4,
        position: [1.0, 2.0],
        crb: Some([[0.01, 0.002], [0.002, 0.03]]),
        peb_m: Some(0.2),
        anchors_used: vec![],
        degraded: false,
    };
    let pose = estimate_pose(&estimate, Time::default());
    let c = pose.pose.covariance.0;
    assert_eq!((c[0], c[1], c[6], c[7]), (0.01, 0.002, 0.002, 0.03));
    assert_eq!(c[35], UNKNOWN_VARIANCE);
    let singular = PositionEstimate {
        crb: None,
        ..estimate
    };
    assert_eq!(
        estimate_pose(&singular, Time::default()).pose.covariance.0[0],
        UNKNOWN_VARIANCE
    );
}

#[test]
fn plan_requests_are_checked() {
    let mut request = PlanDowntimeRequest {
        budget_s: 60.0,
        ..PlanDowntimeRequest::default()
    };
    request.goal.pose.position.x = 6.0;
    let ok = plan_downtime_request(&request).expect("ok");
    assert_eq!(
        (ok.model, ok.deadline_s, ok.goal),
        (PlannerModel::Model1, 5.0, [6.0, 0.0])
    );
    let mut nan = request.clone();
    nan.start.pose.position.x = f64::NAN;
    let refused = plan_downtime_request(&nan).expect_err("nan");
    assert_eq!(refused.code, ErrorCode::InvalidRequest);
    assert!(refused.message.contains("start"), "{refused}");
    for bad in [
        PlanDowntimeRequest {
            budget_s: f64::NAN,
            ..request.clone()
        },
        PlanDowntimeRequest {
            budget_s: 0.0,
            ..request.clone()
        },
        PlanDowntimeRequest {
            deadline_s: -1.0,
            ..request.clone()
        },
        PlanDowntimeRequest {
            model: "model9".into(),
            ..request.clone()
        },
    ] {
        assert!(plan_downtime_request(&bad).is_err(), "{bad:?}");
    }
    let mut frame = request;
    frame.goal.header.frame_id = "odom".into();
    assert!(plan_downtime_request(&frame)
        .expect_err("frame")
        .message
        .contains("odom"));
}

#[test]
fn refusals_fill_the_error_fields() {
    let error = ErrorReply::limit("max_plan_cost", 10, 20, "too big");
    let response = plan_downtime_refusal(&error, Time::default());
    assert_eq!(response.error_code, "limit_exceeded");
    assert!(response.error_message.contains("max_plan_cost"));
    assert!(response.path.poses.is_empty());
}
