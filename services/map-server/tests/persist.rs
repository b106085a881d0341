//! The data dir's files: snapshots that verify before they become the previous copy,
//! size and name checks before anything is read, the change log with its torn tails,
//! replay and compaction, and deletion.

use std::fs::{self, File, OpenOptions};
use std::io::Write;
use std::path::Path;

use roam_map_server::derived::{Derivation, Recipe};
use roam_map_server::edits::CellEdits;
use roam_map_server::persist::{snapshot, Compaction, DataDir, Tombstone, DEFAULT_COMPACTION};
use roam_proto::cells::Cells;
use roam_proto::map::{GridMeta, Layer, Origin};

const MAX_CELLS: u64 = 16_777_216;

fn layer(name: &str, version: u64, fill: f32) -> Layer {
    Layer {
        name: name.into(),
        version,
        meta: GridMeta {
            width: 4,
            height: 3,
            resolution: 0.05,
            origin: Origin::default(),
        },
        derived_from: None,
        cells: Cells::F32(vec![fill; 12]),
    }
}

fn one_cell(x: u32, y: u32, value: f32) -> CellEdits {
    CellEdits {
        positions: vec![(x, y)],
        values: Cells::F32(vec![value]),
    }
}

fn open(dir: &Path) -> DataDir {
    DataDir::open(dir, MAX_CELLS).expect("open")
}

/// Loads a fresh `DataDir` on `dir`: what a restart sees.
fn reload(dir: &Path) -> (Vec<Layer>, Vec<String>) {
    let loaded = open(dir).load_all();
    let layers = loaded
        .layers
        .into_iter()
        .filter_map(|r| r.layer.map(|(l, _)| l))
        .collect();
    (layers, loaded.warnings)
}

fn corrupt_last_byte(path: &Path) {
    let mut bytes = fs::read(path).expect("read");
    let last = bytes.len() - 1;
    bytes[last] ^= 0x40;
    fs::write(path, bytes).expect("write");
}

#[test]
fn a_snapshot_and_its_derivation_load_back() {
    let dir = tempfile::tempdir().expect("tmp");
    let mut data = open(dir.path());
    let mut inflated = layer("inflated", 3, 0.0);
    inflated.derived_from = Some("occupancy".into());
    inflated.cells = Cells::I8(vec![100; 12]);
    let derivation = Derivation {
        source_version: 7,
        recipe: Recipe::Inflate {
            robot_radius_m: 0.25,
            lethal_threshold: 65,
        },
    };
    data.snapshot(&inflated, Some(&derivation)).expect("save");
    let loaded = open(dir.path()).load_all();
    assert!(loaded.warnings.is_empty(), "{:?}", loaded.warnings);
    assert_eq!(
        loaded.layers[0].layer,
        Some((inflated, Some(derivation))),
        "content and derivation"
    );
}

#[test]
fn a_truncated_snapshot_falls_back_to_the_previous_copy_and_is_kept() {
    let dir = tempfile::tempdir().expect("tmp");
    let mut data = open(dir.path());
    data.snapshot(&layer("peb", 1, 0.0), None).expect("save");
    data.snapshot(&layer("peb", 2, 1.0), None).expect("save");
    let path = data.path_of("peb");
    let bytes = fs::read(&path).expect("read");
    fs::write(&path, &bytes[..bytes.len() - 3]).expect("truncate");
    let loaded = open(dir.path()).load_all();
    let recovered = &loaded.layers[0];
    assert_eq!(
        recovered.layer.as_ref().map(|(l, _)| l.clone()),
        Some(layer("peb", 1, 0.0))
    );
    assert_eq!(
        recovered.highest_seen, 2,
        "the truncated file's header counts"
    );
    let all = loaded.warnings.join("\n");
    assert!(all.contains("peb.layer is corrupt: truncated"), "{all}");
    assert!(all.contains("last good copy"), "{all}");
    assert!(path.with_extension("layer.corrupt").exists());
}

#[test]
fn a_flipped_byte_fails_the_crc_and_without_a_previous_copy_nothing_loads() {
    let dir = tempfile::tempdir().expect("tmp");
    let mut data = open(dir.path());
    data.snapshot(&layer("peb", 1, 0.0), None).expect("save");
    corrupt_last_byte(&data.path_of("peb"));
    let loaded = open(dir.path()).load_all();
    assert_eq!(loaded.layers[0].layer, None);
    assert!(loaded.found);
    let all = loaded.warnings.join("\n");
    assert!(all.contains("CRC-32"), "{all}");
    assert!(all.contains("no readable copy"), "{all}");
}

/// The attack: the current file corrupted twice while the server runs. Each snapshot
/// reads the current file back first; a bad one is moved aside and never becomes
/// `.prev`, so `.prev` stays the last file that verified.
#[test]
fn the_previous_copy_is_never_a_file_that_did_not_verify() {
    let dir = tempfile::tempdir().expect("tmp");
    let mut data = open(dir.path());
    let path = data.path_of("peb");
    let prev = path.with_extension("layer.prev");
    data.snapshot(&layer("peb", 1, 1.0), None).expect("save");
    data.snapshot(&layer("peb", 2, 2.0), None).expect("save");
    for (version, fill) in [(3, 3.0), (4, 4.0)] {
        corrupt_last_byte(&path);
        let warnings = data
            .snapshot(&layer("peb", version, fill), None)
            .expect("save");
        assert!(
            warnings
                .iter()
                .any(|w| w.contains("not made the previous copy")),
            "{warnings:?}"
        );
        let kept = snapshot::read(&prev, "peb", MAX_CELLS).expect("the previous copy verifies");
        assert_eq!(kept.layer, layer("peb", 1, 1.0), "still the last good one");
        assert!(path.with_extension("layer.corrupt").exists());
    }
    // And once the current file verifies again, it becomes the previous copy.
    data.snapshot(&layer("peb", 5, 5.0), None).expect("save");
    let kept = snapshot::read(&prev, "peb", MAX_CELLS).expect("verifies");
    assert_eq!(kept.layer.version, 4);
}

/// A sparse 2 GiB file costs no disk and must cost no memory: it is refused on its
/// size, before anything of it is read, naming the limit.
#[test]
fn an_oversized_file_is_refused_before_reading_naming_the_limit() {
    let dir = tempfile::tempdir().expect("tmp");
    let data = open(dir.path());
    let path = data.path_of("peb");
    File::create(&path)
        .and_then(|f| f.set_len(2 * 1024 * 1024 * 1024))
        .expect("sparse file");
    let err = snapshot::read(&path, "peb", MAX_CELLS).expect_err("refused");
    let message = err.error.to_string();
    assert!(message.contains("max_layer_cells = 16777216"), "{message}");
    assert!(message.contains("it was not read"), "{message}");
    let (layers, warnings) = reload(dir.path());
    assert!(layers.is_empty());
    assert!(
        warnings
            .iter()
            .any(|w| w.contains("over the largest layer file")),
        "{warnings:?}"
    );
}

#[test]
fn a_header_must_name_its_own_layer() {
    let dir = tempfile::tempdir().expect("tmp");
    let mut data = open(dir.path());
    data.snapshot(&layer("occupancy_copy", 1, 0.0), None)
        .expect("save");
    // Another layer's file under this layer's name.
    fs::copy(data.path_of("occupancy_copy"), data.path_of("peb")).expect("copy");
    let err = snapshot::read(&data.path_of("peb"), "peb", MAX_CELLS).expect_err("refused");
    assert!(
        err.error
            .to_string()
            .contains("names another layer, not 'peb'"),
        "{}",
        err.error
    );
    // A header naming something that is not a layer name at all.
    let bytes = fs::read(data.path_of("occupancy_copy")).expect("read");
    let text = String::from_utf8_lossy(&bytes).replacen("occupancy_copy", "a/**/b", 1);
    fs::write(data.path_of("x"), text.as_bytes()).expect("write");
    let err = snapshot::read(&data.path_of("x"), "x", MAX_CELLS).expect_err("refused");
    let message = err.error.to_string();
    assert!(message.contains("names no valid layer"), "{message}");
    assert!(
        !message.contains("/**/"),
        "file content is not quoted: {message}"
    );
    // The same for a change log.
    data.append("occupancy_copy", 2, 0, &one_cell(0, 0, 1.0))
        .expect("append");
    fs::copy(
        data.log_path_of("occupancy_copy"),
        data.log_path_of("other"),
    )
    .expect("copy");
    let loaded = open(dir.path()).load_all();
    assert!(
        loaded
            .warnings
            .iter()
            .any(|w| w.contains("other.log is corrupt: its header names another layer")),
        "{:?}",
        loaded.warnings
    );
    // A file whose name is not a layer name is ignored with a warning.
    fs::write(dir.path().join("layers/a b.layer"), b"x").expect("write");
    let (layers, warnings) = reload(dir.path());
    assert_eq!(
        layers.iter().map(|l| l.name.as_str()).collect::<Vec<_>>(),
        ["occupancy_copy"]
    );
    assert!(
        warnings.iter().any(|w| w.contains("is not a layer name")),
        "{warnings:?}"
    );
}

#[test]
fn bad_headers_are_described_without_their_content() {
    let dir = tempfile::tempdir().expect("tmp");
    let data = open(dir.path());
    fs::write(
        data.path_of("peb"),
        b"{\"format\": \"roam-layer\", \"secret\": \"do-not-print\"}\n",
    )
    .expect("write");
    let err = snapshot::read(&data.path_of("peb"), "peb", MAX_CELLS).expect_err("refused");
    let message = err.error.to_string();
    assert!(message.contains("line 1, column"), "{message}");
    assert!(
        !message.contains("secret") && !message.contains("do-not-print"),
        "{message}"
    );
}

#[test]
fn logged_changes_replay_on_top_of_their_snapshot() {
    let dir = tempfile::tempdir().expect("tmp");
    let mut data = open(dir.path());
    data.snapshot(&layer("peb", 1, 0.0), None).expect("save");
    data.append("peb", 2, 0, &one_cell(1, 1, 5.0))
        .expect("append");
    data.append("peb", 3, 0, &one_cell(2, 2, 6.0))
        .expect("append");
    let (layers, warnings) = reload(dir.path());
    assert!(warnings.is_empty(), "{warnings:?}");
    let mut expected = layer("peb", 3, 0.0);
    if let Cells::F32(c) = &mut expected.cells {
        c[5] = 5.0;
        c[10] = 6.0;
    }
    assert_eq!(layers, vec![expected]);
}

/// A crash during an append leaves part of a record: it was never acknowledged, so it
/// is dropped, the log is cut back, and appends go on after the good records.
#[test]
fn a_torn_last_record_is_dropped_and_the_log_goes_on() {
    let dir = tempfile::tempdir().expect("tmp");
    let mut data = open(dir.path());
    data.snapshot(&layer("peb", 1, 0.0), None).expect("save");
    data.append("peb", 2, 0, &one_cell(1, 1, 5.0))
        .expect("append");
    let log = data.log_path_of("peb");
    let good = fs::metadata(&log).expect("log").len();
    // The first 20 bytes of the next record, as a crash would leave them.
    let record = roam_map_server::persist::log::encode(3, 0, &one_cell(2, 2, 6.0));
    OpenOptions::new()
        .append(true)
        .open(&log)
        .and_then(|mut f| f.write_all(&record[..20]))
        .expect("torn append");

    let mut data = open(dir.path());
    let loaded = data.load_all();
    let restored = loaded.layers[0].layer.as_ref().map(|(l, _)| l.version);
    assert_eq!(restored, Some(2));
    assert!(
        loaded
            .warnings
            .iter()
            .any(|w| w.contains("dropped an incomplete last record of 20 bytes")),
        "{:?}",
        loaded.warnings
    );
    assert_eq!(fs::metadata(&log).expect("log").len(), good, "cut back");
    data.append("peb", 3, 0, &one_cell(2, 2, 6.0))
        .expect("append");
    let (layers, warnings) = reload(dir.path());
    assert!(warnings.is_empty(), "{warnings:?}");
    assert_eq!(layers[0].version, 3);
    assert_eq!(layers[0].cells.get_f64(10), Some(6.0));
}

#[test]
fn a_bad_record_inside_the_log_ends_the_replay_and_the_log_is_kept() {
    let dir = tempfile::tempdir().expect("tmp");
    let mut data = open(dir.path());
    data.snapshot(&layer("peb", 1, 0.0), None).expect("save");
    data.append("peb", 2, 0, &one_cell(1, 1, 5.0))
        .expect("append");
    let log = data.log_path_of("peb");
    let after_first = fs::metadata(&log).expect("log").len();
    data.append("peb", 3, 0, &one_cell(2, 2, 6.0))
        .expect("append");
    data.append("peb", 4, 0, &one_cell(3, 2, 7.0))
        .expect("append");
    // Flip a value byte of record 3 (the last bytes of its payload).
    let mut bytes = fs::read(&log).expect("read");
    let record_len = roam_map_server::persist::log::record_bytes(1, roam_proto::cells::Dtype::F32);
    bytes[(after_first + record_len - 1) as usize] ^= 0x01;
    fs::write(&log, bytes).expect("write");
    let loaded = open(dir.path()).load_all();
    let recovered = &loaded.layers[0];
    assert_eq!(recovered.layer.as_ref().map(|(l, _)| l.version), Some(2));
    assert!(recovered.rewrite);
    let all = loaded.warnings.join("\n");
    assert!(all.contains("fails its CRC-32"), "{all}");
    assert!(log.with_extension("log.corrupt").exists(), "kept: {all}");
}

/// Compaction rotates the log with its snapshot; losing the current snapshot then
/// loses nothing: the previous copy and both logs chain up to the last version.
#[test]
fn compaction_rotates_the_log_and_a_lost_snapshot_loses_no_change() {
    let dir = tempfile::tempdir().expect("tmp");
    let mut data = open(dir.path()).with_compaction(Compaction {
        max_log_records: 3,
        ..DEFAULT_COMPACTION
    });
    let mut current = layer("peb", 1, 0.0);
    data.snapshot(&current, None).expect("save");
    let mut compactions = 0;
    for version in 2..=9u64 {
        let edits = one_cell((version % 4) as u32, (version % 3) as u32, version as f32);
        data.append("peb", version, 0, &edits).expect("append");
        edits.apply(&current.meta, &mut current.cells);
        current.version = version;
        if data.should_compact("peb") {
            data.snapshot(&current, None).expect("compact");
            compactions += 1;
        }
    }
    assert_eq!(compactions, 2, "every third record");
    assert!(data.log_path_of("peb").with_extension("log.prev").exists());
    let (layers, _) = reload(dir.path());
    assert_eq!(layers, vec![current.clone()]);

    corrupt_last_byte(&data.path_of("peb"));
    let (layers, warnings) = reload(dir.path());
    assert_eq!(layers, vec![current], "{warnings:?}");
}

#[test]
fn a_deleted_layer_leaves_no_file_and_its_tombstone() {
    let dir = tempfile::tempdir().expect("tmp");
    let mut data = open(dir.path());
    data.snapshot(&layer("peb", 1, 0.0), None).expect("save");
    data.append("peb", 2, 0, &one_cell(1, 1, 5.0))
        .expect("append");
    data.snapshot(&layer("peb", 3, 0.0), None).expect("save");
    let tombstone = Tombstone {
        name: "peb".into(),
        version: 3,
    };
    data.delete("peb", std::slice::from_ref(&tombstone))
        .expect("delete");
    let left: Vec<_> = fs::read_dir(dir.path().join("layers"))
        .expect("dir")
        .filter_map(Result::ok)
        .map(|e| e.file_name())
        .collect();
    assert!(left.is_empty(), "{left:?}");
    let loaded = open(dir.path()).load_all();
    assert!(loaded.layers.is_empty());
    assert_eq!(loaded.tombstones, vec![tombstone]);
}

/// A crash after the tombstone was written but before the files were removed: the
/// next start finishes the deletion.
#[test]
fn a_deletion_cut_short_is_finished_at_the_next_start() {
    let dir = tempfile::tempdir().expect("tmp");
    let mut data = open(dir.path());
    data.snapshot(&layer("peb", 4, 0.0), None).expect("save");
    data.save_tombstones(&[Tombstone {
        name: "peb".into(),
        version: 4,
    }])
    .expect("tombstones");
    let loaded = open(dir.path()).load_all();
    assert!(loaded.layers.is_empty());
    assert!(!data.path_of("peb").exists());
}
