//! The layer store's rules: versions, stale refusals, derived layers, limits.

use roam_map_server::persist::DataDir;
use roam_map_server::store::{
    DerivedParams, LayerStore, Limits, Publication, StoreError, DEFAULT_LIMITS, HEURISTIC,
    INFLATED, INFORMATION, OCCUPANCY,
};
use roam_proto::cells::Cells;
use roam_proto::layer_delta::CellPositions;
use roam_proto::map::{CellWrite, GridMeta, LayerChange, LayerUpdate, Origin};
use roam_proto::ErrorCode;
use roam_world::grid::{occupancy, Grid};

fn meta(w: u32, h: u32) -> GridMeta {
    GridMeta {
        width: w,
        height: h,
        resolution: 0.1,
        origin: Origin::default(),
    }
}

fn store_with_map(limits: Limits) -> LayerStore {
    let mut store = LayerStore::new(limits, DerivedParams::default(), None);
    store
        .load_map(Grid::filled(meta(20, 10), occupancy::FREE), None, None)
        .expect("load");
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

#[test]
fn loading_a_map_creates_sources_and_derived_layers_at_version_1() {
    let store = store_with_map(DEFAULT_LIMITS);
    for name in [OCCUPANCY, INFLATED, INFORMATION, HEURISTIC] {
        assert_eq!(store.version(name), 1, "{name}");
    }
    assert_eq!(
        store.get(INFLATED).and_then(|l| l.derived_from.as_deref()),
        Some(OCCUPANCY)
    );
}

#[test]
fn an_update_bumps_the_layer_and_its_derived_layer() {
    let mut store = store_with_map(DEFAULT_LIMITS);
    let (ack, changed) = store
        .apply(OCCUPANCY, &set(1, &[(5, 5, 100.0)]))
        .expect("apply");
    assert_eq!(ack.version, 2);
    assert_eq!(
        ack.derived
            .iter()
            .map(|d| d.name.as_str())
            .collect::<Vec<_>>(),
        vec![INFLATED]
    );
    assert!(changed.iter().any(|p| p.name() == INFLATED));
    let inflated = store.get(INFLATED).expect("inflated");
    assert_eq!(inflated.version, 2);
    // Robot radius 0.2 m = 2 cells: (7, 5) is inflated, (8, 5) is not.
    assert_eq!(inflated.cells.get_f64(5 * 20 + 7), Some(100.0));
    assert_eq!(inflated.cells.get_f64(5 * 20 + 8), Some(0.0));
}

#[test]
fn a_stale_update_is_refused_and_changes_nothing() {
    let mut store = store_with_map(DEFAULT_LIMITS);
    store
        .apply(OCCUPANCY, &set(1, &[(1, 1, 100.0)]))
        .expect("first writer");
    let err = store
        .apply(OCCUPANCY, &set(1, &[(2, 2, 100.0)]))
        .expect_err("must be refused");
    assert!(
        matches!(
            err,
            StoreError::Stale {
                base: 1,
                current: 2,
                ..
            }
        ),
        "{err}"
    );
    assert_eq!(err.to_reply().code, ErrorCode::StaleVersion);
    assert_eq!(
        store
            .get(OCCUPANCY)
            .and_then(|l| l.cells.get_f64(2 * 20 + 2)),
        Some(0.0)
    );
}

#[test]
fn derived_layers_cannot_be_written() {
    let mut store = store_with_map(DEFAULT_LIMITS);
    let err = store
        .apply(INFLATED, &set(1, &[(1, 1, 0.0)]))
        .expect_err("must be refused");
    assert!(
        err.to_string().contains("update 'occupancy' instead"),
        "{err}"
    );
}

#[test]
fn bad_cells_are_refused_with_what_to_fix() {
    let mut store = store_with_map(DEFAULT_LIMITS);
    let err = store
        .apply(OCCUPANCY, &set(1, &[(20, 0, 0.0)]))
        .expect_err("must be refused");
    assert!(
        err.to_string()
            .contains("outside layer 'occupancy' (20x10)"),
        "{err}"
    );
    let err = store
        .apply(OCCUPANCY, &set(1, &[(0, 0, 101.0)]))
        .expect_err("must be refused");
    assert!(err.to_string().contains("-1..=100"), "{err}");
    let err = store
        .apply(INFORMATION, &set(1, &[(0, 0, f64::NAN)]))
        .expect_err("must be refused");
    assert_eq!(err.to_reply().code, ErrorCode::InvalidRequest);
}

#[test]
fn limits_are_named_in_the_error() {
    let limits = Limits {
        max_cells_per_update: 2,
        max_layer_cells: 300,
        max_layers: 5,
        ..DEFAULT_LIMITS
    };
    let mut store = store_with_map(limits);
    let err = store
        .apply(OCCUPANCY, &set(1, &[(0, 0, 0.0), (1, 0, 0.0), (2, 0, 0.0)]))
        .expect_err("must be refused");
    let reply = err.to_reply();
    assert_eq!(reply.code, ErrorCode::LimitExceeded);
    let hit = reply.limit.expect("limit");
    assert_eq!(
        (hit.name.as_str(), hit.max, hit.actual),
        ("max_cells_per_update", 2, 3)
    );

    let big = LayerUpdate {
        base_version: 0,
        change: LayerChange::Replace {
            meta: meta(20, 20),
            cells: Cells::F32(vec![0.0; 400]),
        },
        world: None,
    };
    let reply = store
        .apply("peb", &big)
        .expect_err("must be refused")
        .to_reply();
    assert_eq!(
        reply.limit.map(|l| l.name),
        Some("max_layer_cells".to_owned())
    );
}

#[test]
fn free_layers_are_created_at_version_0_and_owned_by_their_writer() {
    let mut store = store_with_map(DEFAULT_LIMITS);
    let create = LayerUpdate {
        base_version: 0,
        change: LayerChange::Replace {
            meta: meta(4, 2),
            cells: Cells::F32(vec![0.5; 8]),
        },
        world: None,
    };
    let (ack, _) = store.apply("change_rate", &create).expect("create");
    assert_eq!(ack.version, 1);
    let again = store
        .apply("change_rate", &create)
        .expect_err("must be refused");
    assert!(matches!(again, StoreError::Stale { .. }));
    let wrong_size = LayerUpdate {
        base_version: 0,
        change: LayerChange::Replace {
            meta: meta(4, 2),
            cells: Cells::F32(vec![0.5; 7]),
        },
        world: None,
    };
    assert!(store
        .apply("other", &wrong_size)
        .expect_err("must be refused")
        .to_string()
        .contains("7 cells"));
}

#[test]
fn the_information_map_must_match_the_occupancy_grid() {
    let mut store = store_with_map(DEFAULT_LIMITS);
    let replace = LayerUpdate {
        base_version: 1,
        change: LayerChange::Replace {
            meta: meta(5, 5),
            cells: Cells::U8(vec![10; 25]),
        },
        world: None,
    };
    let err = store
        .apply(INFORMATION, &replace)
        .expect_err("must be refused");
    assert!(err.to_string().contains("occupancy grid's size"), "{err}");
}

#[test]
fn persisted_layers_restore_with_their_versions() {
    let dir = tempfile::tempdir().expect("tmp");
    {
        let mut store = LayerStore::new(
            DEFAULT_LIMITS,
            DerivedParams::default(),
            Some(DataDir::open(dir.path(), DEFAULT_LIMITS.max_layer_cells).expect("dir")),
        );
        store
            .load_map(Grid::filled(meta(20, 10), occupancy::FREE), None, None)
            .expect("load");
        store
            .apply(OCCUPANCY, &set(1, &[(3, 3, 100.0)]))
            .expect("apply");
    }
    let mut store = LayerStore::new(
        DEFAULT_LIMITS,
        DerivedParams::default(),
        Some(DataDir::open(dir.path(), DEFAULT_LIMITS.max_layer_cells).expect("dir")),
    );
    assert!(store.restore(false).expect("restore").found);
    assert_eq!(store.version(OCCUPANCY), 2);
    assert_eq!(store.version(INFLATED), 2);
    assert_eq!(store.version(HEURISTIC), 1);
    assert_eq!(
        store
            .get(OCCUPANCY)
            .and_then(|l| l.cells.get_f64(3 * 20 + 3)),
        Some(100.0)
    );
}

fn replace_f32(base_version: u64, w: u32, h: u32) -> LayerUpdate {
    LayerUpdate {
        base_version,
        change: LayerChange::Replace {
            meta: meta(w, h),
            cells: Cells::F32(vec![0.0; (w * h) as usize]),
        },
        world: None,
    }
}

/// A one-cell update is published as the cell (a delta from the version it was based
/// on), which turns a follower's copy into the store's; a change of many cells goes
/// out whole.
#[test]
fn a_small_update_is_published_as_a_delta_and_a_large_one_whole() {
    let mut store = store_with_map(DEFAULT_LIMITS);
    store.apply("peb", &replace_f32(0, 64, 64)).expect("create");
    let mut follower = store.get("peb").expect("peb").clone();

    let (_, published) = store
        .apply("peb", &set(1, &[(3, 4, 0.5)]))
        .expect("one cell");
    let [Publication::Delta(delta)] = published.as_slice() else {
        panic!("one delta expected, got {published:?}");
    };
    assert_eq!((delta.base_version, delta.version), (1, 2));
    assert_eq!(delta.positions, CellPositions(vec![(3, 4)]));
    assert_eq!(delta.values, Cells::F32(vec![0.5]));
    delta.apply(&mut follower).expect("applies");
    assert_eq!(Some(&follower), store.get("peb"));

    let many: Vec<(u32, u32, f64)> = (0..1000).map(|i| (i % 64, i / 64, 1.0)).collect();
    let (_, published) = store.apply("peb", &set(2, &many)).expect("many cells");
    assert_eq!(published, vec![Publication::Whole("peb".into())]);

    // Occupancy's delta, and its derived layer's (whole or delta), both at the new version.
    let (ack, published) = store
        .apply(OCCUPANCY, &set(1, &[(5, 5, 100.0)]))
        .expect("occupancy");
    assert_eq!(ack.version, 2);
    assert!(
        matches!(&published[0], Publication::Delta(d) if d.name == OCCUPANCY && d.version == 2)
    );
    assert!(published.iter().any(|p| p.name() == INFLATED));
}

/// The cells of all layers together stay within `max_total_cell_bytes`: a replace or a
/// load that would hold more is refused, naming the limit, before anything changes; a
/// replace of a layer counts its old cells as freed, and deleting frees them.
#[test]
fn the_cells_of_all_layers_together_are_bounded() {
    // The 20 x 10 map: occupancy, inflated, information (200 bytes each) and a 4 x 2
    // heuristic of f32 (32 bytes).
    let base = 3 * 200 + 32;
    let limits = Limits {
        max_total_cell_bytes: base + 800,
        ..DEFAULT_LIMITS
    };
    let mut store = store_with_map(limits);
    assert_eq!(store.held_cell_bytes(), base);
    store
        .apply("a", &replace_f32(0, 10, 10))
        .expect("400 bytes fit");
    store
        .apply("b", &replace_f32(0, 10, 10))
        .expect("800 bytes fit");
    assert_eq!(store.held_cell_bytes(), base + 800);
    let refused = store
        .apply("c", &replace_f32(0, 1, 1))
        .expect_err("over the budget")
        .to_reply();
    assert_eq!(refused.code, ErrorCode::LimitExceeded);
    let hit = refused.limit.expect("limit");
    assert_eq!(
        (hit.name.as_str(), hit.max, hit.actual),
        ("max_total_cell_bytes", base + 800, base + 804)
    );
    assert!(
        refused.message.contains("max_total_cell_bytes"),
        "{}",
        refused.message
    );
    assert!(store.get("c").is_none());
    // Replacing a layer with one of the same size holds no more.
    store
        .apply("b", &replace_f32(1, 10, 10))
        .expect("same size");
    // A larger map is refused whole: occupancy stays as it was.
    let refused = store
        .load_map(Grid::filled(meta(40, 40), occupancy::FREE), None, None)
        .expect_err("a larger map");
    assert_eq!(
        refused.to_reply().limit.map(|l| l.name),
        Some("max_total_cell_bytes".to_owned())
    );
    assert_eq!(store.version(OCCUPANCY), 1);
    // Deleting frees the room.
    store.delete("a", 1).expect("delete");
    store.apply("c", &replace_f32(0, 1, 1)).expect("fits again");
}

/// What the budget foresees for a load is what the load then holds (the derived layers
/// included): a budget of exactly that admits it, one byte less does not.
#[test]
fn the_budget_foresees_a_load_exactly() {
    let mut store = store_with_map(DEFAULT_LIMITS);
    store
        .load_map(Grid::filled(meta(40, 40), occupancy::FREE), None, None)
        .expect("load");
    let exact = store.held_cell_bytes();
    for (max, fits) in [(exact, true), (exact - 1, false)] {
        let mut store = store_with_map(Limits {
            max_total_cell_bytes: max,
            ..DEFAULT_LIMITS
        });
        let outcome = store.load_map(Grid::filled(meta(40, 40), occupancy::FREE), None, Some(1));
        assert_eq!(outcome.is_ok(), fits, "max {max}: {outcome:?}");
    }
}

fn replace(base_version: u64, meta: GridMeta, cells: Cells) -> LayerUpdate {
    LayerUpdate {
        base_version,
        change: LayerChange::Replace { meta, cells },
        world: None,
    }
}

/// A map of another size (a new map from ROS 2, a new map file) is a new world: the free
/// layers on the old grid are forgotten, the base layers follow the new grid, the world
/// id changes; a new map on the same grid changes none of that.
#[test]
fn occupancy_on_another_grid_forgets_the_layers_of_the_old_one() {
    let mut store = store_with_map(DEFAULT_LIMITS);
    store
        .set_world(roam_world::world_id::world_id(
            "site",
            &Grid::filled(meta(20, 10), occupancy::FREE),
        ))
        .expect("world");
    let before = store.world().cloned().expect("world");
    store
        .apply("news", &replace(0, meta(20, 10), Cells::U8(vec![7; 200])))
        .expect("news");
    let same_grid = Cells::I8(vec![occupancy::OCCUPIED; 200]);
    store
        .apply(OCCUPANCY, &replace(1, meta(20, 10), same_grid))
        .expect("same grid");
    assert_eq!(store.version("news"), 1, "a map on the same grid keeps it");
    assert_eq!(store.world(), Some(&before));

    let bigger = Cells::I8(vec![occupancy::FREE; 30 * 12]);
    store
        .apply(OCCUPANCY, &replace(2, meta(30, 12), bigger))
        .expect("bigger");
    assert!(store.get("news").is_none(), "the old grid's layer is gone");
    // (heuristic is information compressed by c_h: on its own coarser grid.)
    for name in [OCCUPANCY, INFLATED, INFORMATION] {
        let layer = store.get(name).expect(name);
        assert_eq!((layer.meta.width, layer.meta.height), (30, 12), "{name}");
    }
    assert_eq!(store.version(HEURISTIC), 2);
    let after = store.world().cloned().expect("world");
    assert_ne!(after.hash, before.hash, "another grid is another world");
    assert_eq!(after.name, "site");
    // Written again on the new grid, the layer goes on from its last version.
    let (ack, _) = store
        .apply("news", &replace(0, meta(30, 12), Cells::U8(vec![1; 360])))
        .expect("news again");
    assert_eq!(ack.version, 2);
}
