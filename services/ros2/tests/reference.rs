//! roam's CDR and hashes against PyPI's `rosbags` 0.11.9, an independent implementation
//! of ROS 2 messages: the bytes and hashes below are what
//! `tests/reference/rosbags_reference.py` prints.

use roam_ros2::msg::*;
use roam_ros2::{cdr, hash, types};

fn hex(text: &str) -> Vec<u8> {
    (0..text.len())
        .step_by(2)
        .map(|i| u8::from_str_radix(&text[i..i + 2], 16).expect("hex"))
        .collect()
}

fn header() -> Header {
    Header {
        stamp: Time {
            sec: 1_700_000_000,
            nanosec: 5,
        },
        frame_id: "map".into(),
    }
}

fn pose(x: f64, y: f64, z: f64, w: f64) -> Pose {
    Pose {
        position: Point { x, y, z: 0.0 },
        orientation: Quaternion {
            x: 0.0,
            y: 0.0,
            z,
            w,
        },
    }
}

const OCCUPANCY_GRID: &str = "0001000000f1536505000000040000006d6170000100000002000000cdcc4c3e03000000020000000000000000000000000024c000000000000014c00000000000000000000000000000000000000000000000000000000000000000000000000000f03f06000000ff0064320000";
const PATH: &str = "0001000000f1536505000000040000006d6170000200000000f1536505000000040000006d61700000000000000000000000f83f00000000000000c00000000000000000000000000000000000000000000000000000000000000000000000000000f03f00f1536505000000040000006d617000000000000000004000000000000000c0000000000000000000000000000000000000000000000000000000000000e03f000000000000e83f";
const POSE_WITH_COVARIANCE_STAMPED: &str = "0001000000f1536505000000040000006d617000000000000000f03f00000000000000400000000000000000000000000000000000000000000000000000000000000000000000000000f03f0000000000000000000000000000f03f000000000000004000000000000008400000000000001040000000000000144000000000000018400000000000001c40000000000000204000000000000022400000000000002440000000000000264000000000000028400000000000002a400000000000002c400000000000002e4000000000000030400000000000003140000000000000324000000000000033400000000000003440000000000000354000000000000036400000000000003740000000000000384000000000000039400000000000003a400000000000003b400000000000003c400000000000003d400000000000003e400000000000003f400000000000004040000000000080404000000000000041400000000000804140";

#[test]
fn an_occupancy_grid_is_byte_for_byte_rosbags_s() {
    let grid = OccupancyGrid {
        header: header(),
        info: MapMetaData {
            map_load_time: Time { sec: 1, nanosec: 2 },
            resolution: 0.2,
            width: 3,
            height: 2,
            origin: Pose {
                position: Point {
                    x: -10.0,
                    y: -5.0,
                    z: 0.0,
                },
                orientation: Quaternion::default(),
            },
        },
        data: vec![-1, 0, 100, 50, 0, 0],
    };
    let bytes = hex(OCCUPANCY_GRID);
    assert_eq!(cdr::encode(&grid).expect("encode"), bytes);
    assert_eq!(
        cdr::decode::<OccupancyGrid>(&bytes, "map", 1 << 20),
        Ok(grid)
    );
}

#[test]
fn a_path_is_byte_for_byte_rosbags_s() {
    let stamped = |pose| PoseStamped {
        header: header(),
        pose,
    };
    let path = Path {
        header: header(),
        poses: vec![
            stamped(pose(1.5, -2.0, 0.0, 1.0)),
            stamped(pose(2.0, -2.0, 0.5, 0.75)),
        ],
    };
    let bytes = hex(PATH);
    assert_eq!(cdr::encode(&path).expect("encode"), bytes);
    assert_eq!(cdr::decode::<Path>(&bytes, "path", 1 << 20), Ok(path));
}

#[test]
fn a_pose_with_covariance_is_byte_for_byte_rosbags_s() {
    let mut covariance = [0.0; 36];
    for (i, c) in covariance.iter_mut().enumerate() {
        *c = i as f64;
    }
    let message = PoseWithCovarianceStamped {
        header: header(),
        pose: PoseWithCovariance {
            pose: pose(1.0, 2.0, 0.0, 1.0),
            covariance: Covariance(covariance),
        },
    };
    let bytes = hex(POSE_WITH_COVARIANCE_STAMPED);
    assert_eq!(cdr::encode(&message).expect("encode"), bytes);
    assert_eq!(
        cdr::decode::<PoseWithCovarianceStamped>(&bytes, "pose", 1 << 20),
        Ok(message)
    );
}

#[test]
fn the_service_hashes_are_rosbags_s() {
    assert_eq!(
        hash::service_type_hash(types::PLAN_DOWNTIME).as_deref(),
        Ok("RIHS01_d5e249ca4b3504320f17348ec589584120a6a8f3c771adfe56a3f951f221bba6")
    );
    assert_eq!(
        hash::service_type_hash(types::GET_PLAN).as_deref(),
        Ok("RIHS01_234f7aff100f5edb8150366601687b027bcdc253db47decb88fff846193fe5e8")
    );
}

/// Nav2's planner and controller actions, tf2's message and the clock, hashed by rosbags (the action's services
/// built as rosidl builds them, as for roam's own services above).
/// `action_msgs/msg/GoalStatusArray`'s hash is also the one ROS 2 Jazzy publishes.
#[test]
fn the_action_and_tf_hashes_are_rosbags_s() {
    for (service, rosbags) in [
        (
            types::COMPUTE_PATH_SEND_GOAL,
            "RIHS01_e800806a220935f225495784663dfdd78b509335309a5127ed1112f6ce6b9dbc",
        ),
        (
            types::COMPUTE_PATH_GET_RESULT,
            "RIHS01_386ab12c2f62a441596ef1140b3beca654a957eaac87e769c10de01b0e28208f",
        ),
        (
            types::CANCEL_GOAL,
            "RIHS01_573d8b0a534451d7bc2ac8c5ffde8ac14b8593b7001175d0cd6516dcbeb8689a",
        ),
        (
            types::FOLLOW_PATH_SEND_GOAL,
            "RIHS01_5b662aee1159e1d7e7b5f8fef21f556b8bc67c818c730a68e18bb29b85f66946",
        ),
        (
            types::FOLLOW_PATH_GET_RESULT,
            "RIHS01_8ab4c588c878f0e997316ec559f172bb56fc210b484c2f6b280d391d3bd6890f",
        ),
    ] {
        assert_eq!(
            hash::service_type_hash(service).as_deref(),
            Ok(rosbags),
            "{service}"
        );
    }
    for (message, rosbags) in [
        (
            types::COMPUTE_PATH_FEEDBACK_MESSAGE,
            "RIHS01_a086c8f040554ab5883b433bded128a1d1a732d21ca57596b7fdbe7ad2d0b64a",
        ),
        (
            types::GOAL_STATUS_ARRAY,
            "RIHS01_6c1684b00f177d37438febe6e709fc4e2b0d4248dca4854946f9ed8b30cda83e",
        ),
        (
            types::TF_MESSAGE,
            "RIHS01_e369d0f05a23ae52508854b66f6aa0437f3449d652e8cbf22d5abe85d020f087",
        ),
        (
            types::FOLLOW_PATH_FEEDBACK_MESSAGE,
            "RIHS01_3f4008700ba56ac4c82b01ef2b7fdd3fc18dc194399c48e5c43ebf8008b891d5",
        ),
        (
            types::CLOCK,
            "RIHS01_692f7a66e93a3c83e71765d033b60349ba68023a8c689a79e48078bcb5c58564",
        ),
    ] {
        assert_eq!(
            hash::message_type_hash(message).as_deref(),
            Ok(rosbags),
            "{message}"
        );
    }
}
