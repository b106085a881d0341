//! What a restart gives back: derived layers in step with their sources whatever the
//! files went through, versions that never go back, the configured map for a source
//! with no readable copy, deletions remembered, and small changes that cost small
//! appends.

use std::fs;
use std::path::Path;

use roam_map_server::persist::{Compaction, DataDir, DEFAULT_COMPACTION};
use roam_map_server::service::open_store;
use roam_map_server::store::{
    DerivedParams, LayerStore, StoreError, DEFAULT_LIMITS, HEURISTIC, INFLATED, INFORMATION,
    OCCUPANCY,
};
use roam_map_server::MapServerConfig;
use roam_proto::cells::Cells;
use roam_proto::map::{CellWrite, GridMeta, Layer, LayerChange, LayerUpdate, Origin};
use roam_proto::ErrorCode;
use roam_world::grid::{occupancy, Grid};
use roam_world::layers;

fn meta(w: u32, h: u32) -> GridMeta {
    GridMeta {
        width: w,
        height: h,
        resolution: 0.1,
        origin: Origin::default(),
    }
}

fn store_on(dir: &Path) -> LayerStore {
    store_with(dir, DEFAULT_COMPACTION)
}

fn store_with(dir: &Path, compaction: Compaction) -> LayerStore {
    let data = DataDir::open(dir, DEFAULT_LIMITS.max_layer_cells).expect("data dir");
    LayerStore::new(
        DEFAULT_LIMITS,
        DerivedParams::default(),
        Some(data.with_compaction(compaction)),
    )
}

fn restarted(dir: &Path) -> LayerStore {
    let mut store = store_on(dir);
    let restored = store.restore(false).expect("restore");
    assert!(restored.found);
    assert!(restored.lost_sources.is_empty(), "{restored:?}");
    store
}

fn set(base_version: u64, cells: &[(u32, u32, f64)]) -> LayerUpdate {
    LayerUpdate {
        base_version,
        change: LayerChange::SetCells {
            cells: cells
                .iter()
                .map(|&(x, y, value)| CellWrite { x, y, value })
                .collect(),
        },
        world: None,
    }
}

fn layers_dir(dir: &Path) -> std::path::PathBuf {
    dir.join("layers")
}

/// `inflated` is exactly occupancy inflated with the store's parameters, it says so,
/// and every obstacle of occupancy is occupied in it.
fn assert_in_step(store: &LayerStore) {
    let occ = store.get(OCCUPANCY).expect("occupancy");
    let inflated = store.get(INFLATED).expect("inflated");
    let Cells::I8(cells) = &occ.cells else {
        panic!("occupancy is i8")
    };
    let params = store.derived_params();
    let expected = layers::inflate(
        &Grid {
            meta: occ.meta,
            cells: cells.clone(),
        },
        params.robot_radius_m,
        params.lethal_threshold,
    );
    assert_eq!(inflated.cells, Cells::I8(expected.cells));
    for (i, &c) in cells.iter().enumerate() {
        if c >= params.lethal_threshold {
            assert_eq!(inflated.cells.get_f64(i), Some(100.0), "obstacle cell {i}");
        }
    }
    assert_eq!(
        store.derivation(INFLATED).map(|d| d.source_version),
        Some(occ.version)
    );
    assert_eq!(
        store.derivation(HEURISTIC).map(|d| d.source_version),
        Some(store.version(INFORMATION))
    );
    assert!(
        inflated.version >= occ.version,
        "a derived layer is never behind"
    );
}

fn warnings(store: &LayerStore) -> String {
    store.list().warnings.join("\n")
}

/// A SIGKILL between the save of occupancy and the save of inflated: occupancy's log
/// has the change, inflated's does not.
#[test]
fn a_kill_between_the_two_saves_gives_an_inflated_computed_again() {
    let dir = tempfile::tempdir().expect("tmp");
    let mut store = store_on(dir.path());
    store
        .load_map(Grid::filled(meta(40, 30), occupancy::FREE), None, None)
        .expect("load");
    store
        .apply(OCCUPANCY, &set(1, &[(10, 10, 100.0)]))
        .expect("v2");
    // Inflated's record of version 2 never reached the disk.
    fs::remove_file(layers_dir(dir.path()).join("inflated.log")).expect("inflated log");
    drop(store);

    let store = restarted(dir.path());
    assert_eq!(store.version(OCCUPANCY), 2);
    assert_eq!(
        store
            .get(OCCUPANCY)
            .and_then(|l| l.cells.get_f64(10 * 40 + 10)),
        Some(100.0)
    );
    assert_in_step(&store);
    assert!(store.version(INFLATED) >= 2, "never back");
    let all = warnings(&store);
    assert!(
        all.contains("'inflated' computed again from 'occupancy' version 2"),
        "{all}"
    );
    assert!(all.contains("computed from version 1"), "{all}");

    // It was persisted: the next start has nothing to compute.
    let again = restarted(dir.path());
    assert_in_step(&again);
    assert!(
        !warnings(&again).contains("computed again"),
        "{}",
        warnings(&again)
    );
}

#[test]
fn an_inflated_with_no_readable_copy_is_computed_again() {
    let dir = tempfile::tempdir().expect("tmp");
    let mut store = store_on(dir.path());
    store
        .load_map(Grid::filled(meta(30, 30), occupancy::FREE), None, None)
        .expect("load");
    store
        .apply(OCCUPANCY, &set(1, &[(3, 4, 100.0)]))
        .expect("v2");
    drop(store);
    for file in ["inflated.layer", "inflated.log"] {
        fs::remove_file(layers_dir(dir.path()).join(file)).expect("remove");
    }
    let store = restarted(dir.path());
    assert_in_step(&store);
    assert!(
        warnings(&store).contains("had no readable copy"),
        "{}",
        warnings(&store)
    );
}

/// A fallback to `.prev` moves occupancy back to older content: it is served above
/// every version seen, and inflated is computed again from it.
#[test]
fn a_fallback_to_the_previous_copy_keeps_derived_layers_in_step_and_versions_up() {
    let dir = tempfile::tempdir().expect("tmp");
    let mut store = store_on(dir.path());
    let mut first = Grid::filled(meta(30, 20), occupancy::FREE);
    first.cells[5 * 30 + 5] = occupancy::OCCUPIED;
    store.load_map(first.clone(), None, None).expect("v1");
    let mut second = first.clone();
    second.cells[15 * 30 + 25] = occupancy::OCCUPIED;
    store.load_map(second, None, Some(1)).expect("v2");
    assert_eq!(store.version(INFLATED), 2);
    drop(store);
    // The current occupancy snapshot (version 2) is damaged on disk.
    let path = layers_dir(dir.path()).join("occupancy.layer");
    let mut bytes = fs::read(&path).expect("read");
    let last = bytes.len() - 1;
    bytes[last] ^= 0x01;
    fs::write(&path, bytes).expect("write");

    let store = restarted(dir.path());
    let occ = store.get(OCCUPANCY).expect("occupancy");
    assert_eq!(occ.cells, Cells::I8(first.cells), "the last good content");
    assert_eq!(occ.version, 3, "above the lost version 2");
    assert!(store.version(INFLATED) >= 3, "inflated never goes back");
    assert_in_step(&store);
    let all = warnings(&store);
    assert!(all.contains("last good copy"), "{all}");
    assert!(all.contains("served as version 3"), "{all}");
}

/// Neither `occupancy.layer` nor `.prev` readable (the current file corrupted twice
/// while running, then a restart): the configured map is loaded again, above the last
/// version, with a warning that says so.
#[test]
fn with_no_readable_copy_of_occupancy_the_configured_map_is_loaded_again() {
    let dir = tempfile::tempdir().expect("tmp");
    let config = MapServerConfig {
        data_dir: Some(dir.path().to_owned()),
        ..MapServerConfig::default()
    };
    let mut store = open_store(&config).expect("fresh start");
    let builtin = store.get(OCCUPANCY).expect("occupancy").clone();
    store
        .apply(OCCUPANCY, &set(1, &[(1, 1, 100.0)]))
        .expect("v2");
    let layer_info: Layer = store.get(INFORMATION).expect("information").clone();
    drop(store);
    for file in ["occupancy.layer", "occupancy.log"] {
        fs::write(layers_dir(dir.path()).join(file), b"garbage").expect("corrupt");
    }

    let store = open_store(&config).expect("restart");
    let occ = store.get(OCCUPANCY).expect("occupancy is served");
    assert_eq!(occ.cells, builtin.cells, "the built-in world again");
    assert_eq!(occ.version, 3, "above version 2, which inflated had seen");
    assert_in_step(&store);
    assert_eq!(
        store.get(INFORMATION).map(|l| &l.cells),
        Some(&layer_info.cells),
        "the readable information map is kept"
    );
    let all = warnings(&store);
    assert!(
        all.contains("layer 'occupancy' had no readable copy in the data dir: the configured map <built-in downtime world> was loaded again, as version 3"),
        "{all}"
    );
}

#[test]
fn the_robot_radius_inflated_was_computed_with_survives_a_restart() {
    let dir = tempfile::tempdir().expect("tmp");
    let mut store = store_on(dir.path());
    store.set_robot_radius(0.5);
    store
        .load_map(Grid::filled(meta(30, 30), occupancy::FREE), None, None)
        .expect("load");
    drop(store);
    let store = restarted(dir.path());
    assert_eq!(
        store.derived_params().robot_radius_m,
        0.5,
        "kept, not the default"
    );
    assert!(!warnings(&store).contains("computed again"));

    // A radius the config sets wins, and inflated is computed again with it.
    let mut store = store_on(dir.path());
    store.set_robot_radius(0.3);
    store.restore(true).expect("restore");
    assert_eq!(store.derived_params().robot_radius_m, 0.3);
    assert_in_step(&store);
    assert!(
        warnings(&store).contains("computed with robot radius 0.5 m and lethal threshold 65, the config now asks for robot radius 0.3 m"),
        "{}",
        warnings(&store)
    );
}

/// Many small changes, compacted on the way, come back exactly; the logs stay within
/// the compaction's bound.
#[test]
fn logged_changes_and_compactions_restore_exactly() {
    let dir = tempfile::tempdir().expect("tmp");
    let mut store = store_with(
        dir.path(),
        Compaction {
            max_log_records: 40,
            ..DEFAULT_COMPACTION
        },
    );
    store
        .load_map(Grid::filled(meta(64, 64), occupancy::FREE), None, None)
        .expect("load");
    for i in 0..300u32 {
        let v = store.version(OCCUPANCY);
        let value = if i % 3 == 0 { 0.0 } else { 100.0 };
        store
            .apply(OCCUPANCY, &set(v, &[(i % 64, (i * 7) % 64, value)]))
            .expect("update");
        let v = store.version(INFORMATION);
        store
            .apply(
                INFORMATION,
                &set(v, &[((i * 3) % 64, i % 64, f64::from(i % 101))]),
            )
            .expect("update");
    }
    let before: Vec<Layer> = [OCCUPANCY, INFLATED, INFORMATION, HEURISTIC]
        .iter()
        .map(|n| store.get(n).expect("layer").clone())
        .collect();
    assert_in_step(&store);
    drop(store);
    let store = restarted(dir.path());
    let after: Vec<Layer> = [OCCUPANCY, INFLATED, INFORMATION, HEURISTIC]
        .iter()
        .map(|n| store.get(n).expect("layer").clone())
        .collect();
    assert_eq!(after, before);
    assert!(warnings(&store).is_empty(), "{}", warnings(&store));
    // 300 changes, compacted every 40: the logs hold fewer than 40 records each.
    let record = roam_map_server::persist::log::record_bytes(1, roam_proto::cells::Dtype::I8);
    let log = fs::metadata(layers_dir(dir.path()).join("occupancy.log")).map_or(0, |m| m.len());
    assert!(log < 40 * record + 100, "log of {log} bytes");
    assert!(
        layers_dir(dir.path()).join("occupancy.log.prev").exists(),
        "compacted"
    );
}

/// The cost that scales with the change: one cell of a 4096 × 4096 f32 layer (64 MiB)
/// appends well under 1 KiB to the data dir.
#[test]
fn a_one_cell_update_to_a_maximum_size_layer_appends_under_1_kib() {
    let dir = tempfile::tempdir().expect("tmp");
    let mut store = store_on(dir.path());
    store
        .load_map(Grid::filled(meta(8, 8), occupancy::FREE), None, None)
        .expect("load");
    let side = 4096u32;
    let create = LayerUpdate {
        base_version: 0,
        change: LayerChange::Replace {
            meta: meta(side, side),
            cells: Cells::F32(vec![0.0; (side * side) as usize]),
        },
        world: None,
    };
    store.apply("peb", &create).expect("create");
    let size = |dir: &Path| -> u64 {
        fs::read_dir(layers_dir(dir))
            .expect("dir")
            .filter_map(Result::ok)
            .filter_map(|e| e.metadata().ok())
            .map(|m| m.len())
            .sum()
    };
    let before = size(dir.path());
    for i in 0..10u32 {
        let v = store.version("peb");
        store
            .apply("peb", &set(v, &[(100 + i, 2000, 1.5)]))
            .expect("update");
    }
    let grown = size(dir.path()) - before;
    assert!(grown < 1024, "ten one-cell updates appended {grown} bytes");
    drop(store);
    let store = restarted(dir.path());
    assert_eq!(store.version("peb"), 11);
    assert_eq!(
        store
            .get("peb")
            .and_then(|l| l.cells.get_f64(2000 * 4096 + 109)),
        Some(1.5)
    );
}

fn create_free(store: &mut LayerStore, name: &str, base: u64) -> u64 {
    let update = LayerUpdate {
        base_version: base,
        change: LayerChange::Replace {
            meta: meta(4, 4),
            cells: Cells::F32(vec![0.25; 16]),
        },
        world: None,
    };
    store.apply(name, &update).expect("create").0.version
}

#[test]
fn a_free_layer_is_deleted_and_a_new_one_goes_on_from_its_version() {
    let dir = tempfile::tempdir().expect("tmp");
    let mut store = store_on(dir.path());
    store
        .load_map(Grid::filled(meta(4, 4), occupancy::FREE), None, None)
        .expect("load");
    create_free(&mut store, "peb", 0);
    store.apply("peb", &set(1, &[(0, 0, 1.0)])).expect("v2");

    let stale = store.delete("peb", 1).expect_err("stale");
    assert_eq!(stale.to_reply().code, ErrorCode::StaleVersion);
    for base in ["occupancy", "inflated", "information", "heuristic"] {
        let refused = store
            .delete(base, store.version(base))
            .expect_err("protected");
        assert!(matches!(refused, StoreError::Protected { .. }), "{refused}");
        assert_eq!(refused.to_reply().code, ErrorCode::InvalidRequest);
        assert!(
            refused.to_string().contains("cannot be deleted"),
            "{refused}"
        );
    }
    let deleted = store.delete("peb", 2).expect("deleted");
    assert_eq!((deleted.layer.as_str(), deleted.version), ("peb", 2));
    assert!(store.get("peb").is_none());
    assert!(!store.list().layers.iter().any(|l| l.name == "peb"));
    let missing = store.delete("peb", 2).expect_err("gone");
    assert_eq!(missing.to_reply().code, ErrorCode::NotFound);
    assert!(!layers_dir(dir.path()).join("peb.layer").exists());
    assert!(!layers_dir(dir.path()).join("peb.log").exists());
    drop(store);

    // After a restart the deletion holds, and a new layer goes on from version 2.
    let mut store = restarted(dir.path());
    assert!(store.get("peb").is_none());
    assert_eq!(create_free(&mut store, "peb", 0), 3);
    drop(store);
    let store = restarted(dir.path());
    assert_eq!(store.version("peb"), 3);
}

/// `max_layers` slots cannot be squatted for good: deleting frees one.
#[test]
fn deleting_a_layer_frees_its_slot() {
    let mut store = LayerStore::new(
        roam_map_server::store::Limits {
            max_layers: 5,
            ..DEFAULT_LIMITS
        },
        DerivedParams::default(),
        None,
    );
    store
        .load_map(Grid::filled(meta(4, 4), occupancy::FREE), None, None)
        .expect("load");
    create_free(&mut store, "a", 0);
    let full = LayerUpdate {
        base_version: 0,
        change: LayerChange::Replace {
            meta: meta(4, 4),
            cells: Cells::F32(vec![0.0; 16]),
        },
        world: None,
    };
    let refused = store.apply("b", &full).expect_err("full");
    assert_eq!(
        refused.to_reply().limit.map(|l| l.name),
        Some("max_layers".into())
    );
    store.delete("a", 1).expect("delete");
    store.apply("b", &full).expect("a slot again");
}

/// A change one of whose layers cannot be persisted is refused, not applied, and what
/// was already written for the others is undone: the files never hold it.
#[test]
fn a_change_that_cannot_be_persisted_is_refused_and_leaves_no_trace() {
    use roam_map_server::persist::log;

    let dir = tempfile::tempdir().expect("tmp");
    let mut store = store_on(dir.path());
    store
        .load_map(Grid::filled(meta(40, 30), occupancy::FREE), None, None)
        .expect("load");
    store
        .apply(OCCUPANCY, &set(1, &[(10, 10, 100.0)]))
        .expect("v2");
    // inflated's log cannot be appended to any more.
    let inflated_log = layers_dir(dir.path()).join("inflated.log");
    fs::remove_file(&inflated_log).expect("remove");
    fs::create_dir(&inflated_log).expect("a folder in its place");

    let err = store
        .apply(OCCUPANCY, &set(2, &[(20, 20, 100.0)]))
        .expect_err("refused");
    assert_eq!(err.to_reply().code, ErrorCode::Internal);
    assert!(err.to_string().contains("could not be persisted"), "{err}");
    assert_eq!(store.version(OCCUPANCY), 2, "not applied");
    let at = |s: &LayerStore| s.get(OCCUPANCY).and_then(|l| l.cells.get_f64(20 * 40 + 20));
    assert_eq!(at(&store), Some(0.0));
    let occupancy_log = layers_dir(dir.path()).join("occupancy.log");
    let scan = log::scan(&occupancy_log, OCCUPANCY, u64::MAX, u64::MAX).expect("scan");
    assert_eq!(
        scan.records.iter().map(|r| r.version).collect::<Vec<_>>(),
        [2],
        "occupancy's record of the refused change was cut off again"
    );

    fs::remove_dir(&inflated_log).expect("folder");
    drop(store);
    let store = restarted(dir.path());
    assert_eq!(store.version(OCCUPANCY), 2);
    assert_eq!(at(&store), Some(0.0));
    assert_in_step(&store);
}
