//! ROS map_server maps read and written with Nav2's rules.

use std::path::{Path, PathBuf};

use roam_world::grid::occupancy;
use roam_world::grid::DEFAULT_MAX_CELLS;
use roam_world::ros_map::{self, count_cells, CellCounts, MapMode, RosMapError, SaveParams};

fn maps_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../config/maps")
}

const MAX: u64 = DEFAULT_MAX_CELLS;

/// The expected counts were computed outside roam, by a short Python script that reads
/// the PGM bytes, histograms the pixel values and applies Nav2's trinary rule
/// (`occ = 1 - v/255`; occupied if `occ > occupied_thresh`, free if `occ < free_thresh`):
/// depot has 5947 pixels at 0, 8894 at 205 and 170587 at 254; with its free_thresh of
/// 0.25 the 205 pixels (occ 0.196) are free. tb3_sandbox has 870 at 0, 138683 at 205 and
/// 7903 at 254; its free_thresh of 0.196 leaves the 205 pixels (occ 0.19608) unknown.
#[test]
fn nav2_maps_give_nav2_counts() {
    let depot = ros_map::load(&maps_dir().join("depot.yaml"), MAX).expect("depot");
    assert_eq!((depot.grid.meta.width, depot.grid.meta.height), (604, 307));
    assert_eq!(
        count_cells(&depot.grid),
        CellCounts {
            occupied: 5947,
            free: 179_481,
            unknown: 0
        }
    );
    let sandbox = ros_map::load(&maps_dir().join("tb3_sandbox.yaml"), MAX).expect("sandbox");
    assert_eq!(
        (sandbox.grid.meta.width, sandbox.grid.meta.height),
        (384, 384)
    );
    assert_eq!(
        sandbox.params.mode,
        MapMode::Trinary,
        "mode defaults to trinary"
    );
    assert_eq!(sandbox.grid.meta.origin.x, -10.0);
    assert_eq!(
        count_cells(&sandbox.grid),
        CellCounts {
            occupied: 870,
            free: 7903,
            unknown: 138_683
        }
    );
}

/// Writes a PGM with the given rows (top row first) and a yaml, returns the yaml path.
fn write_map(dir: &Path, rows: &[&[u8]], yaml_extra: &str) -> PathBuf {
    let (w, h) = (rows[0].len(), rows.len());
    let mut pgm = format!("P5\n{w} {h}\n255\n").into_bytes();
    for row in rows {
        pgm.extend_from_slice(row);
    }
    std::fs::write(dir.join("m.pgm"), pgm).expect("pgm");
    let yaml = format!("image: m.pgm\nresolution: 0.1\norigin: [1.0, 2.0, 0.0]\noccupied_thresh: 0.65\nfree_thresh: 0.196\n{yaml_extra}");
    let path = dir.join("m.yaml");
    std::fs::write(&path, yaml).expect("yaml");
    path
}

#[test]
fn image_row_zero_is_the_top_of_the_map() {
    let dir = tempfile::tempdir().expect("tmp");
    let yaml = write_map(dir.path(), &[&[0, 254], &[254, 254]], "");
    let map = ros_map::load(&yaml, MAX).expect("load");
    // The black pixel is top-left in the image: grid row 1 (the top), column 0.
    assert_eq!(map.grid.get(0, 1), Some(occupancy::OCCUPIED));
    assert_eq!(map.grid.get(0, 0), Some(occupancy::FREE));
}

#[test]
fn negate_swaps_black_and_white() {
    let dir = tempfile::tempdir().expect("tmp");
    let yaml = write_map(dir.path(), &[&[0, 254, 205]], "negate: 1\n");
    let map = ros_map::load(&yaml, MAX).expect("load");
    assert_eq!(
        map.grid.cells,
        vec![occupancy::FREE, occupancy::OCCUPIED, occupancy::OCCUPIED]
    );
}

#[test]
fn scale_mode_interpolates_between_the_thresholds() {
    let dir = tempfile::tempdir().expect("tmp");
    // occ = 1 - v/255: v=128 → 0.498 → rint((0.498-0.196)/(0.65-0.196)*100) = 67.
    let yaml = write_map(dir.path(), &[&[0, 255, 128]], "mode: scale\n");
    let map = ros_map::load(&yaml, MAX).expect("load");
    let expected =
        (((1.0 - 128.0 / 255.0) - 0.196) / (0.65 - 0.196) * 100.0f64).round_ties_even() as i8;
    assert_eq!(expected, 67);
    assert_eq!(
        map.grid.cells,
        vec![occupancy::OCCUPIED, occupancy::FREE, 67]
    );
}

#[test]
fn raw_mode_keeps_values_up_to_100() {
    let dir = tempfile::tempdir().expect("tmp");
    let yaml = write_map(dir.path(), &[&[0, 37, 100, 101, 255]], "mode: raw\n");
    let map = ros_map::load(&yaml, MAX).expect("load");
    assert_eq!(map.grid.cells, vec![0, 37, 100, -1, -1]);
}

#[test]
fn saved_maps_load_back_identical() {
    let dir = tempfile::tempdir().expect("tmp");
    let depot = ros_map::load(&maps_dir().join("tb3_sandbox.yaml"), MAX).expect("sandbox");
    let out = dir.path().join("saved.yaml");
    ros_map::save(&depot.grid, &out, SaveParams::default()).expect("save");
    let bytes = std::fs::read(dir.path().join("saved.pgm")).expect("pgm");
    assert!(bytes.starts_with(b"P5\n"), "a binary PGM");
    let back = ros_map::load(&out, MAX).expect("reload");
    assert_eq!(back.grid.meta, depot.grid.meta);
    assert!(
        back.grid.cells == depot.grid.cells,
        "cells differ after a round trip"
    );
}

#[test]
fn bad_maps_are_refused_naming_the_file() {
    let dir = tempfile::tempdir().expect("tmp");
    let missing = dir.path().join("nope.yaml");
    assert!(matches!(
        ros_map::load(&missing, MAX),
        Err(RosMapError::Missing { .. })
    ));

    let yaml = write_map(dir.path(), &[&[0, 254]], "");
    std::fs::write(dir.path().join("m.pgm"), b"P5\n2 1\n255\n").expect("truncate");
    let err = ros_map::load(&yaml, MAX).expect_err("must be refused");
    assert!(matches!(err, RosMapError::Image { .. }), "{err}");
    assert!(err.to_string().contains("m.pgm"), "{err}");

    let yaml = write_map(dir.path(), &[&[0, 254], &[0, 0]], "");
    let err = ros_map::load(&yaml, 3).expect_err("must be refused");
    assert!(err.to_string().contains("max_layer_cells is 3"), "{err}");

    std::fs::write(
        &yaml,
        "image: m.pgm\nresolution: -1\norigin: [0,0,0]\noccupied_thresh: 0.65\nfree_thresh: 0.2\n",
    )
    .expect("yaml");
    let err = ros_map::load(&yaml, MAX).expect_err("must be refused");
    assert!(err.to_string().contains("resolution"), "{err}");
}

/// A FIFO (or a device) as a map path would block the reader forever: it is refused at
/// once with an error that says why.
#[test]
fn a_fifo_is_refused_not_read() {
    let dir = tempfile::tempdir().expect("tmp");
    let fifo = dir.path().join("map.yaml");
    let made = std::process::Command::new("mkfifo")
        .arg(&fifo)
        .status()
        .expect("mkfifo");
    assert!(made.success());
    let started = std::time::Instant::now();
    let err = roam_world::scenario::load_any(&fifo, 1 << 22).expect_err("refused");
    assert!(started.elapsed() < std::time::Duration::from_secs(2));
    assert!(err.to_string().contains("not a regular file"), "{err}");
    let err =
        roam_world::ros_map::read_bounded(std::path::Path::new("/dev/zero")).expect_err("a device");
    assert!(err.to_string().contains("not a regular file"), "{err}");
}

/// A ROS map at 3 cm loads as a scenario: the observation radius it did not set is the
/// default cut to the limit in cells (128 cells, 3.84 m), while a scenario that sets 5 m
/// on the same map is refused naming the field.
#[test]
fn a_fine_ros_map_loads_with_an_observation_radius_that_fits_it() {
    let dir = tempfile::tempdir().expect("tmp");
    let mut pgm = b"P5\n200 150\n255\n".to_vec();
    pgm.extend(std::iter::repeat_n(254u8, 200 * 150));
    std::fs::write(dir.path().join("fine.pgm"), pgm).expect("pgm");
    let yaml = dir.path().join("fine.yaml");
    std::fs::write(
        &yaml,
        "image: fine.pgm\nresolution: 0.03\norigin: [0.0, 0.0, 0.0]\n\
         occupied_thresh: 0.65\nfree_thresh: 0.196\n",
    )
    .expect("yaml");
    let scenario = roam_world::scenario::load_any(&yaml, MAX).expect("a 3 cm map loads");
    assert!((scenario.file.sensing.observation_radius_m - 3.84).abs() < 1e-9);
    assert_eq!(
        roam_world::scenario::fitted_observation_radius_m(5.0, 0.2),
        5.0
    );
    let own = dir.path().join("site.yaml");
    std::fs::write(
        &own,
        format!(
            "name: site\nmap: {{ ros: {} }}\nsensing: {{ observation_radius_m: 5.0 }}\n",
            yaml.file_name().and_then(|n| n.to_str()).expect("name")
        ),
    )
    .expect("site");
    let refused = roam_world::scenario::load(&own, MAX).expect_err("5 m at 3 cm is refused");
    assert!(
        refused.to_string().contains("sensing.observation_radius_m"),
        "{refused}"
    );
}
