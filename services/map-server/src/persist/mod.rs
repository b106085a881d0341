//! Layers on disk, in `<data_dir>/layers/`: per layer a snapshot, a change log, and the
//! previous verified snapshot with its log. The crate's README ("Persistence") is the
//! reference; in short:
//!
//! - `<name>.layer` ([`snapshot`]): the whole layer at some version, with its
//!   derivation for a derived layer;
//! - `<name>.log` ([`log`]): the `set_cells` changes since that snapshot, one
//!   checksummed record per version, fsynced before the change is acknowledged;
//! - `<name>.layer.prev` and `<name>.log.prev`: the snapshot before, hard-linked only
//!   once it was read back and verified, and the log that went on from it;
//! - `<data_dir>/deleted-layers.json` ([`tombstones`]): deleted layers' last versions.
//!
//! A change that writes few cells is appended to the log; a replace, or a change whose
//! record would be larger than a quarter of a snapshot, writes a snapshot. After an
//! append the log is compacted into a fresh snapshot once it outgrows a quarter of the
//! snapshot (at least 64 KiB) or 1,048,576 records ([`Compaction`]), so a layer's files
//! stay within about 2.5 times its size and a restore replays a bounded log.

mod error;
mod loaded;
pub mod log;
mod recovery;
mod small_file;
pub mod snapshot;
pub mod tombstones;
pub mod world;

use std::collections::BTreeMap;
use std::fs;
use std::path::{Path, PathBuf};

use roam_proto::map::Layer;

pub use error::PersistError;
pub use loaded::{Loaded, Recovered};
pub use log::Record;
pub use tombstones::{Tombstone, MAX_TOMBSTONES};

use small_file::sync_dir;

use crate::derived::Derivation;
use crate::edits::CellEdits;

/// When a log is compacted into a fresh snapshot.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Compaction {
    /// A log may grow to 1/`snapshot_share` of its snapshot's size (default 4). A
    /// change whose record alone would be larger writes a snapshot instead.
    pub snapshot_share: u64,
    /// ... but always to this many bytes (default 64 KiB), so a small layer does not
    /// write a snapshot for every change.
    pub min_log_bytes: u64,
    /// And to at most this many records (default 1,048,576), which bounds a restore's
    /// work per record whatever their sizes. High enough that the byte bound governs a
    /// maximum-size layer's one-cell records (about 409,000 of them in 16 MiB): a
    /// compaction there costs its 64 MiB snapshot once per 409,000 updates, about
    /// 160 bytes an update.
    pub max_log_records: u64,
}

pub const DEFAULT_COMPACTION: Compaction = Compaction {
    snapshot_share: 4,
    min_log_bytes: 64 * 1024,
    max_log_records: 1_048_576,
};

/// What the data dir knows of one layer's files while the server runs.
#[derive(Debug, Clone, Default, PartialEq)]
pub(crate) struct LogState {
    /// Length of `<name>.log` (0: no log).
    log_bytes: u64,
    log_records: u64,
    /// Size of the snapshot the log goes on from (0: none yet).
    snapshot_bytes: u64,
    /// The next change must write a snapshot: there is no usable one to append to, or
    /// an append could not be undone.
    needs_snapshot: bool,
    /// The log's length before the last append, to undo it.
    before_last_append: Option<u64>,
}

/// The data directory of a map server.
#[derive(Debug)]
pub struct DataDir {
    root: PathBuf,
    layers: PathBuf,
    max_layer_cells: u64,
    compaction: Compaction,
    logs: BTreeMap<String, LogState>,
}

/// The file kinds of a layer, by suffix; a name with one of them is a layer's.
const LAYER_SUFFIXES: [&str; 4] = [".layer", ".layer.prev", ".log", ".log.prev"];
/// What a crash can leave behind, removed at load.
const TEMP_SUFFIXES: [&str; 2] = [".layer.tmp", ".layer.prev.tmp"];
/// Every file a layer can have, removed when it is deleted.
const ALL_SUFFIXES: [&str; 10] = [
    ".layer",
    ".layer.prev",
    ".log",
    ".log.prev",
    ".layer.tmp",
    ".layer.prev.tmp",
    ".layer.corrupt",
    ".layer.prev.corrupt",
    ".log.corrupt",
    ".log.prev.corrupt",
];

impl DataDir {
    /// Opens (and creates) `<root>/layers`. Layer files are refused when larger than a
    /// layer of `max_layer_cells` cells can be.
    pub fn open(root: &Path, max_layer_cells: u64) -> Result<Self, PersistError> {
        let layers = root.join("layers");
        fs::create_dir_all(&layers).map_err(|e| PersistError::Write {
            path: layers.clone(),
            reason: e.to_string(),
        })?;
        Ok(DataDir {
            root: root.to_owned(),
            layers,
            max_layer_cells,
            compaction: DEFAULT_COMPACTION,
            logs: BTreeMap::new(),
        })
    }

    /// The same data dir with another compaction policy (tests use small ones).
    pub fn with_compaction(mut self, compaction: Compaction) -> Self {
        self.compaction = compaction;
        self
    }

    /// The snapshot file of a layer.
    pub fn path_of(&self, name: &str) -> PathBuf {
        self.path_with(name, ".layer")
    }

    /// The change log of a layer.
    pub fn log_path_of(&self, name: &str) -> PathBuf {
        self.path_with(name, ".log")
    }

    fn path_with(&self, name: &str, suffix: &str) -> PathBuf {
        self.layers.join(format!("{name}{suffix}"))
    }

    fn world_path(&self) -> PathBuf {
        self.root.join("world.json")
    }

    /// Records which world the layers are of.
    pub fn save_world(&self, world: &roam_proto::map::WorldId) -> Result<(), PersistError> {
        world::write(&self.world_path(), world)
    }

    /// The recorded world, if any.
    pub fn load_world(&self) -> Result<Option<roam_proto::map::WorldId>, PersistError> {
        world::read(&self.world_path())
    }

    fn tombstones_path(&self) -> PathBuf {
        self.root.join("deleted-layers.json")
    }

    fn share(&self) -> u64 {
        self.compaction.snapshot_share.max(1)
    }

    /// The largest record the store writes (larger changes write a snapshot), and so the
    /// largest a reader accepts.
    fn max_record_bytes(&self) -> u64 {
        snapshot::max_file_bytes(self.max_layer_cells) / self.share()
    }

    /// The largest log a reader accepts: four times the largest layer file (a log is
    /// compacted at a quarter of its snapshot, so only failing compactions grow one).
    fn max_log_bytes(&self) -> u64 {
        snapshot::max_file_bytes(self.max_layer_cells).saturating_mul(4)
    }

    /// Whether a change of layer `name` whose log record would take `record_bytes`
    /// should rather write a snapshot: there is none to append to yet, the record would
    /// be larger than the log may grow, or an earlier failure asks for one.
    pub fn prefers_snapshot(&self, name: &str, record_bytes: u64) -> bool {
        match self.logs.get(name) {
            None => true,
            Some(s) => {
                s.needs_snapshot
                    || s.snapshot_bytes == 0
                    || record_bytes > s.snapshot_bytes / self.share()
            }
        }
    }

    /// Whether the log of `name` has outgrown its snapshot and should be compacted.
    pub fn should_compact(&self, name: &str) -> bool {
        self.logs.get(name).is_some_and(|s| {
            let max = (s.snapshot_bytes / self.share()).max(self.compaction.min_log_bytes);
            s.log_bytes > max || s.log_records >= self.compaction.max_log_records
        })
    }

    /// Writes a snapshot of `layer`, which from then on is the base its log goes on
    /// from. Returns warnings: a current snapshot that failed its verification (moved
    /// aside, not made the previous copy).
    ///
    /// Steps, each leaving a recoverable state if the process dies after it: write and
    /// fsync `<name>.layer.tmp`; read the current snapshot back and, only if it
    /// verifies, hard-link it to `<name>.layer.prev` and move `<name>.log` to
    /// `<name>.log.prev` (a bad one is moved aside to `.corrupt`); rename the temp
    /// file over `<name>.layer`; fsync the folder; drop the log the new snapshot
    /// replaces when it could not be kept as `.log.prev`.
    pub fn snapshot(
        &mut self,
        layer: &Layer,
        derivation: Option<&Derivation>,
    ) -> Result<Vec<String>, PersistError> {
        let name = layer.name.as_str();
        let path = self.path_of(name);
        let tmp = self.path_with(name, ".layer.tmp");
        let prev = self.path_with(name, ".layer.prev");
        let prev_tmp = self.path_with(name, ".layer.prev.tmp");
        let log_path = self.log_path_of(name);
        let log_prev = self.path_with(name, ".log.prev");
        let write_err = |p: &Path, e: std::io::Error| PersistError::Write {
            path: p.to_owned(),
            reason: e.to_string(),
        };
        let bytes = snapshot::write(&tmp, layer, derivation)?;
        let mut warnings = Vec::new();
        let mut rotated = false;
        if path.exists() {
            match snapshot::read(&path, name, self.max_layer_cells) {
                Ok(_) => {
                    remove_if_exists(&prev_tmp)?;
                    fs::hard_link(&path, &prev_tmp).map_err(|e| write_err(&prev_tmp, e))?;
                    fs::rename(&prev_tmp, &prev).map_err(|e| write_err(&prev, e))?;
                    if log_path.exists() {
                        fs::rename(&log_path, &log_prev).map_err(|e| write_err(&log_prev, e))?;
                    } else {
                        // The previous copy's log went on from an older snapshot.
                        remove_if_exists(&log_prev)?;
                    }
                    rotated = true;
                }
                Err(unreadable) => {
                    let aside = self.path_with(name, ".layer.corrupt");
                    fs::rename(&path, &aside).map_err(|e| write_err(&aside, e))?;
                    warnings.push(format!(
                        "{}; kept as {}, and not made the previous copy (that stays {})",
                        unreadable.error,
                        aside.display(),
                        prev.display()
                    ));
                }
            }
        }
        fs::rename(&tmp, &path).map_err(|e| write_err(&path, e))?;
        sync_dir(&self.layers)?;
        if !rotated && log_path.exists() {
            // Every record in it is older than the new snapshot.
            remove_if_exists(&log_path)?;
            sync_dir(&self.layers)?;
        }
        self.logs.insert(
            name.to_owned(),
            LogState {
                snapshot_bytes: bytes,
                ..LogState::default()
            },
        );
        Ok(warnings)
    }

    /// Appends the change of layer `name` that makes `version` to its log, durably.
    /// `source_version` is the source version a derived layer then follows (else 0).
    pub fn append(
        &mut self,
        name: &str,
        version: u64,
        source_version: u64,
        edits: &CellEdits,
    ) -> Result<(), PersistError> {
        let path = self.log_path_of(name);
        let framed = log::encode(version, source_version, edits);
        let state = self.logs.entry(name.to_owned()).or_default();
        let new_file = state.log_bytes == 0;
        let before = match log::append(&path, name, &framed) {
            Ok(before) => before,
            Err(e) => {
                // A partial record (a full disk, say) must not stay in front of the
                // next one: cut the log back to its good records.
                let good = state.log_bytes;
                let cut = if good == 0 {
                    remove_if_exists(&path)
                } else {
                    log::truncate(&path, good)
                };
                if cut.is_err() {
                    state.needs_snapshot = true;
                }
                return Err(e);
            }
        };
        if new_file {
            sync_dir(&self.layers)?;
        }
        state.log_bytes = before + framed.len() as u64;
        state.log_records += 1;
        state.before_last_append = Some(before);
        Ok(())
    }

    /// Undoes the last append of `name` (its change was not applied after all). When
    /// the log cannot be cut back, the next change writes a snapshot instead.
    pub fn rollback(&mut self, name: &str) {
        let path = self.log_path_of(name);
        let Some(state) = self.logs.get_mut(name) else {
            return;
        };
        let Some(before) = state.before_last_append.take() else {
            return;
        };
        match log::truncate(&path, before) {
            Ok(()) => {
                state.log_bytes = before;
                state.log_records = state.log_records.saturating_sub(1);
            }
            Err(e) => {
                tracing::error!("{e}; the next change of '{name}' writes a snapshot");
                state.needs_snapshot = true;
            }
        }
    }

    /// Makes the next change of `name` write a snapshot (its files may hold a change
    /// that was not applied).
    pub fn require_snapshot(&mut self, name: &str) {
        self.logs.entry(name.to_owned()).or_default().needs_snapshot = true;
    }

    /// Removes the files of a layer the store does not hold (a creation whose commit
    /// failed half-way), so a restart does not bring it back.
    pub fn discard(&mut self, name: &str) -> Result<(), PersistError> {
        self.logs.remove(name);
        self.remove_files(name)
    }

    /// Deletes layer `name`: records `tombstones` (which name it) first, so a crash
    /// half-way is finished at the next start, then removes every file of the layer.
    pub fn delete(&mut self, name: &str, tombstones: &[Tombstone]) -> Result<(), PersistError> {
        self.save_tombstones(tombstones)?;
        self.remove_files(name)?;
        self.logs.remove(name);
        Ok(())
    }

    pub(crate) fn remove_files(&self, name: &str) -> Result<(), PersistError> {
        for suffix in ALL_SUFFIXES {
            remove_if_exists(&self.path_with(name, suffix))?;
        }
        sync_dir(&self.layers)
    }

    /// Writes the deleted layers' last versions.
    pub fn save_tombstones(&self, tombstones: &[Tombstone]) -> Result<(), PersistError> {
        tombstones::write(&self.tombstones_path(), tombstones)
    }
}

fn remove_if_exists(path: &Path) -> Result<(), PersistError> {
    match fs::remove_file(path) {
        Ok(()) => Ok(()),
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => Ok(()),
        Err(e) => Err(PersistError::Write {
            path: path.to_owned(),
            reason: e.to_string(),
        }),
    }
}
