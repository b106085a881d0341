use super::*;
use roam_proto::cells::Cells;
use roam_proto::map::Origin;

fn stamp() -> Timestamp {
    Timestamp::new(1_700_000_000, 5)
}

fn layer(name: &str, cells: Cells, width: u32, height: u32) -> Layer {
    Layer {
        name: name.to_owned(),
        version: 3,
        meta: GridMeta {
            width,
            height,
            resolution: 0.25,
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

fn close(a: f64, b: f64) -> bool {
    (a - b).abs() < 1e-9
}

#[test]
fn numbers_in_metadata_are_short_whatever_the_wire_said() {
    assert_eq!(fixed(12.34567, 3), "12.346");
    assert_eq!(fixed(1e300, 3), "1e300");
    assert_eq!(fixed(-1e300, 4), "-1e300");
    assert_eq!(fixed(f64::NAN, 3), "NaN");
}

#[test]
fn an_occupancy_layer_is_a_grid_of_ros_values_placed_by_its_meta() {
    // 3 wide, 2 high; row 0 (at the origin) is -1 0 100, row 1 is 50 0 -1.
    let l = layer("occupancy", Cells::I8(vec![-1, 0, 100, 50, 0, -1]), 3, 2);
    let g = grid(&l, stamp()).expect("grid");
    assert_eq!(g.frame_id, "map");
    assert_eq!(g.column_count, 3);
    assert_eq!((g.cell_stride, g.row_stride), (1, 3));
    let cell = g.cell_size.expect("cell size");
    assert!(close(cell.x, 0.25) && close(cell.y, 0.25));
    let position = g.pose.and_then(|p| p.position).expect("position");
    assert!(close(position.x, -10.0) && close(position.y, -5.0) && close(position.z, 0.0));
    assert_eq!(g.fields.len(), 1);
    assert_eq!(g.fields[0].name, GRID_FIELD);
    assert_eq!(g.fields[0].r#type, NumericType::Int8 as i32);
    // The bytes are the cells, row 0 first, -1 as 0xff.
    assert_eq!(g.data.as_ref(), &[0xff, 0, 100, 50, 0, 0xff]);
    assert_eq!(g.timestamp, Some(stamp()));
}

#[test]
fn u8_and_f32_layers_keep_their_type_and_values() {
    let info = grid(
        &layer("information", Cells::U8(vec![0, 7, 100, 255]), 2, 2),
        stamp(),
    )
    .expect("grid");
    assert_eq!(info.fields[0].r#type, NumericType::Uint8 as i32);
    assert_eq!(info.data.as_ref(), &[0, 7, 100, 255]);

    let peb = layer("peb", Cells::F32(vec![0.5, f32::INFINITY]), 2, 1);
    let g = grid(&peb, stamp()).expect("grid");
    assert_eq!(g.fields[0].r#type, NumericType::Float32 as i32);
    assert_eq!((g.cell_stride, g.row_stride), (4, 8));
    let values: Vec<f32> = g
        .data
        .chunks_exact(4)
        .map(|c| f32::from_le_bytes([c[0], c[1], c[2], c[3]]))
        .collect();
    assert_eq!(values, vec![0.5, f32::INFINITY]);
}

#[test]
fn a_rotated_origin_rotates_the_grid() {
    let mut l = layer("occupancy", Cells::I8(vec![0; 4]), 2, 2);
    l.meta.origin.yaw = std::f64::consts::FRAC_PI_2;
    let q = grid(&l, stamp())
        .expect("grid")
        .pose
        .and_then(|p| p.orientation)
        .expect("orientation");
    let half = std::f64::consts::FRAC_PI_4;
    assert!(close(q.z, half.sin()) && close(q.w, half.cos()) && close(q.x, 0.0));
}

#[test]
fn a_layer_whose_cells_do_not_fill_its_size_is_refused() {
    let l = layer("occupancy", Cells::I8(vec![0; 5]), 3, 2);
    assert!(matches!(
        grid(&l, stamp()),
        Err(ConvertError::CellCount { cells: 5, .. })
    ));
}

#[test]
fn an_anchor_is_a_cube_standing_on_the_floor_at_its_place() {
    let update = anchors(
        &[
            NamedPoint {
                name: "a1".into(),
                at: [3.5, -2.0],
            },
            NamedPoint {
                name: "a2".into(),
                at: [0.0, 7.25],
            },
        ],
        stamp(),
    );
    assert_eq!(update.entities.len(), 1);
    let e = &update.entities[0];
    assert_eq!((e.id.as_str(), e.frame_id.as_str()), ("anchors", "map"));
    assert_eq!(e.cubes.len(), 2);
    let p = e.cubes[0].pose.and_then(|p| p.position).expect("position");
    assert!(close(p.x, 3.5) && close(p.y, -2.0) && close(p.z, ANCHOR_SIZE_M / 2.0));
    let size = e.cubes[0].size.expect("size");
    assert!(close(size.x, ANCHOR_SIZE_M) && close(size.z, ANCHOR_SIZE_M));
    assert_eq!(e.cubes[0].color, Some(ANCHOR));
    let p2 = e.cubes[1].pose.and_then(|p| p.position).expect("position");
    assert!(close(p2.x, 0.0) && close(p2.y, 7.25));
    let names: Vec<&str> = e.texts.iter().map(|t| t.text.as_str()).collect();
    assert_eq!(names, vec!["a1", "a2"]);
}

#[test]
fn a_true_position_is_a_robot_sphere_at_that_point() {
    let update = truth(
        &GroundTruth {
            robot: "r1".into(),
            step: 4,
            time_s: 1.6,
            at: [1.0, 2.0],
        },
        stamp(),
    );
    let e = &update.entities[0];
    assert_eq!(e.id, "truth/r1");
    let p = e.spheres[0]
        .pose
        .and_then(|p| p.position)
        .expect("position");
    assert!(close(p.x, 1.0) && close(p.y, 2.0));
}

#[test]
fn the_covariance_ellipse_has_the_axes_of_the_covariance() {
    // Variances 4 and 1 along x and y: 2-sigma diameters 8 and 4, along x.
    let (d1, d2, angle) = covariance_ellipse([[4.0, 0.0], [0.0, 1.0]], 2.0).expect("ellipse");
    assert!(close(d1, 8.0) && close(d2, 4.0) && close(angle, 0.0));
    // The same rotated by 90 degrees.
    let (d1, d2, angle) = covariance_ellipse([[1.0, 0.0], [0.0, 4.0]], 2.0).expect("ellipse");
    assert!(close(d1, 8.0) && close(d2, 4.0));
    assert!(close(angle.abs(), std::f64::consts::FRAC_PI_2));
    // Correlated: the major axis along the diagonal.
    let (_, _, angle) = covariance_ellipse([[2.0, 1.0], [1.0, 2.0]], 1.0).expect("ellipse");
    assert!(close(angle, std::f64::consts::FRAC_PI_4));
    assert!(covariance_ellipse([[f64::INFINITY, 0.0], [0.0, 1.0]], 2.0).is_none());
}

#[test]
fn an_estimate_with_a_crb_has_an_ellipse() {
    let p = PositionEstimate {
        robot: "r1".into(),
        step: 1,
        time_s: 0.4,
        position: [1.0, 1.0],
        crb: Some([[0.01, 0.0], [0.0, 0.04]]),
        peb_m: Some(0.2236),
        anchors_used: vec!["a1".into(), "a2".into(), "a3".into()],
        degraded: false,
    };
    let e = &estimate(&p, stamp()).entities[0];
    assert_eq!(e.id, "estimate/r1");
    assert_eq!(e.spheres.len(), 2);
    let size = e.spheres[1].size.expect("size");
    assert!(close(size.x, 0.8) && close(size.y, 0.4));
    let without = PositionEstimate { crb: None, ..p };
    assert_eq!(estimate(&without, stamp()).entities[0].spheres.len(), 1);
}

#[test]
fn a_mission_is_a_line_through_its_waypoints_and_an_empty_one_deletes_it() {
    let m = Mission {
        after_step: None,
        robot: "r1".into(),
        id: "w1".into(),
        waypoints: vec![[0.0, 0.0], [1.0, 0.0], [1.0, 2.0]],
        recovery: false,
    };
    let update = mission(&m, stamp());
    let e = &update.entities[0];
    assert_eq!(e.id, "mission/r1");
    let xy: Vec<(f64, f64)> = e.lines[0].points.iter().map(|p| (p.x, p.y)).collect();
    assert_eq!(xy, vec![(0.0, 0.0), (1.0, 0.0), (1.0, 2.0)]);
    assert_eq!(e.cubes.len(), 3);
    let stop = mission(
        &Mission {
            waypoints: Vec::new(),
            ..m
        },
        stamp(),
    );
    assert!(stop.entities.is_empty());
    assert_eq!(stop.deletions[0].id, "mission/r1");
}

#[test]
fn a_long_mission_is_drawn_within_the_bounds() {
    let m = Mission {
        after_step: None,
        robot: "r1".into(),
        id: "x".repeat(1 << 20),
        waypoints: (0..MAX_WAYPOINTS + 5).map(|i| [i as f64, 0.0]).collect(),
        recovery: false,
    };
    let e = &mission(&m, stamp()).entities[0];
    assert_eq!(e.lines[0].points.len(), MAX_WAYPOINTS);
    assert!(e.cubes.len() <= MISSION_CUBES, "{}", e.cubes.len());
    assert!(e.cubes.len() > MISSION_CUBES / 2, "{}", e.cubes.len());
    let meta: Vec<(&str, &str)> = e
        .metadata
        .iter()
        .map(|kv| (kv.key.as_str(), kv.value.as_str()))
        .collect();
    assert!(meta.contains(&("waypoints", "10005")), "{meta:?}");
    assert!(meta.contains(&("cube_every", "10")), "{meta:?}");
    let id = meta.iter().find(|(k, _)| *k == "mission").expect("id").1;
    assert!(id.len() < 100 && id.ends_with("(1048576 bytes)"), "{id}");
}

#[test]
fn names_from_the_wire_are_escaped_in_ids_labels_and_metadata() {
    let evil = "r1\n\u{1b}[31mred".to_owned();
    let t = truth(
        &GroundTruth {
            robot: evil.clone(),
            step: 1,
            time_s: 0.1,
            at: [0.0, 0.0],
        },
        stamp(),
    );
    let p = PositionEstimate {
        robot: evil.clone(),
        step: 1,
        time_s: 0.4,
        position: [1.0, 1.0],
        crb: None,
        peb_m: None,
        anchors_used: vec![evil.clone(); 100],
        degraded: false,
    };
    let m = Mission {
        after_step: None,
        robot: evil.clone(),
        id: evil.clone(),
        waypoints: vec![[0.0, 0.0]],
        recovery: false,
    };
    let a = anchors(
        &[NamedPoint {
            name: evil.clone(),
            at: [0.0, 0.0],
        }],
        stamp(),
    );
    let mut path = DrivenPath::new(4, 0.0);
    path.push([0.0, 0.0]);
    let d = driven([(evil.as_str(), &path)].into_iter(), stamp());
    for update in [t, estimate(&p, stamp()), mission(&m, stamp()), a, d] {
        let e = &update.entities[0];
        let mut texts = vec![e.id.clone()];
        texts.extend(e.texts.iter().map(|t| t.text.clone()));
        texts.extend(e.metadata.iter().map(|kv| kv.value.clone()));
        for text in texts {
            assert!(
                !text.contains('\n') && !text.contains('\u{1b}'),
                "{text:?} in {}",
                e.id
            );
        }
    }
    let listed = &estimate(&p, stamp()).entities[0].metadata[4].value;
    assert!(listed.ends_with("(+68 more)"), "{listed}");
}

#[test]
fn a_driven_path_is_thinned_and_bounded() {
    let mut path = DrivenPath::new(3, 0.1);
    assert!(path.push([0.0, 0.0]));
    assert!(!path.push([0.05, 0.0]), "closer than the minimum step");
    assert!(path.push([0.2, 0.0]));
    assert!(path.push([0.4, 0.0]));
    assert!(path.push([0.6, 0.0]));
    assert!(!path.push([f64::NAN, 0.0]));
    assert_eq!(path.len(), 3);
    let xs: Vec<f64> = path.points().map(|p| p[0]).collect();
    assert_eq!(xs, vec![0.2, 0.4, 0.6], "the oldest point went");
    let update = driven([("r1", &path)].into_iter(), stamp());
    assert_eq!(update.entities[0].id, "driven/r1");
    assert_eq!(update.entities[0].lines[0].points.len(), 3);
}
