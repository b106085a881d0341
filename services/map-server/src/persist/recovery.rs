//! Putting a layer back together from its files after a restart or a crash.
//!
//! The base is the snapshot `<name>.layer`, or, when it is unreadable, the last verified
//! copy `<name>.layer.prev`. On top of it go the records of `<name>.log.prev` (the log
//! of the previous snapshot) and `<name>.log`, in order, each one that produces the next
//! version; records the base already holds are skipped. So a crash anywhere leaves a
//! complete chain, and losing the current snapshot loses nothing a log still holds.
//!
//! Nothing found wrong is thrown away: an unreadable snapshot is moved aside to
//! `.corrupt`, a log with a bad record in its middle is copied there before it is cut
//! back to its good records. Every problem becomes a warning that names the file.

use std::fs;
use std::path::Path;

use roam_proto::keys;

use super::loaded::{Loaded, Recovered};
use super::log::{self, Tail};
use super::snapshot::{self, Snapshot};
use super::tombstones;
use super::{DataDir, LogState, LAYER_SUFFIXES, TEMP_SUFFIXES};

/// Loads every layer of `dir` (see [`DataDir::load_all`]).
pub(crate) fn load_all(dir: &mut DataDir) -> Loaded {
    let mut loaded = Loaded::default();
    match tombstones::read(&dir.tombstones_path()) {
        Ok(t) => loaded.tombstones = t,
        Err(e) => loaded.warnings.push(format!(
            "{e}; deleted layers are not remembered, so one created again starts at version 1"
        )),
    }
    let entries = match fs::read_dir(&dir.layers) {
        Ok(entries) => entries,
        Err(e) => {
            loaded
                .warnings
                .push(format!("cannot list {}: {e}", dir.layers.display()));
            return loaded;
        }
    };
    let mut names = Vec::new();
    for entry in entries.filter_map(Result::ok) {
        let file = entry.file_name();
        let Some(file) = file.to_str() else {
            loaded.warnings.push(format!(
                "ignored {}: its name is not a layer file's",
                entry.path().display()
            ));
            continue;
        };
        if let Some(stem) = TEMP_SUFFIXES.iter().find_map(|s| file.strip_suffix(s)) {
            if keys::check_name("layer name", stem).is_ok() {
                let _ = fs::remove_file(entry.path());
            }
            continue;
        }
        let Some(stem) = LAYER_SUFFIXES.iter().find_map(|s| file.strip_suffix(s)) else {
            continue;
        };
        if keys::check_name("layer name", stem).is_err() {
            loaded.warnings.push(format!(
                "ignored {}: '{}' is not a layer name",
                entry.path().display(),
                stem.escape_debug()
            ));
            continue;
        }
        names.push(stem.to_owned());
    }
    names.sort();
    names.dedup();
    loaded.found = !names.is_empty();
    let mut tombstones_changed = false;
    for name in names {
        let (recovered, state) = recover(dir, &name, &mut loaded.warnings);
        let tomb = loaded.tombstones.iter().position(|t| t.name == name);
        let newest = recovered
            .layer
            .as_ref()
            .map_or(0, |(l, _)| l.version)
            .max(recovered.highest_seen);
        match tomb {
            Some(i) if newest <= loaded.tombstones[i].version => {
                // Deleted, but the files outlived a crash: finish the deletion.
                if let Err(e) = dir.remove_files(&name) {
                    loaded.warnings.push(format!(
                        "layer '{name}' was deleted, but its files could not be removed: {e}"
                    ));
                }
                continue;
            }
            Some(i) => {
                // Created again after the deletion.
                loaded.tombstones.remove(i);
                tombstones_changed = true;
            }
            None => {}
        }
        if recovered.layer.is_none() {
            loaded.warnings.push(format!(
                "layer '{name}' has no readable copy and was not loaded"
            ));
        }
        dir.logs.insert(name.clone(), state);
        loaded.layers.push(recovered);
    }
    if tombstones_changed {
        if let Err(e) = dir.save_tombstones(&loaded.tombstones) {
            loaded.warnings.push(e.to_string());
        }
    }
    loaded
}

/// Recovers layer `name`: its content, what it says, and the state of its log.
pub(crate) fn recover(
    dir: &DataDir,
    name: &str,
    warnings: &mut Vec<String>,
) -> (Recovered, LogState) {
    let mut recovered = Recovered {
        name: name.to_owned(),
        layer: None,
        highest_seen: 0,
        rewrite: false,
    };
    let mut state = LogState::default();
    let base = base_snapshot(dir, name, &mut recovered, &mut state, warnings);

    let mut records = Vec::new();
    for (path, is_current) in [
        (dir.path_with(name, ".log.prev"), false),
        (dir.log_path_of(name), true),
    ] {
        if !path.exists() {
            continue;
        }
        let scan = match log::scan(&path, name, dir.max_record_bytes(), dir.max_log_bytes()) {
            Ok(scan) => scan,
            Err(e) => {
                warnings.push(format!("{e}; {}", move_aside(&path)));
                recovered.rewrite = true;
                continue;
            }
        };
        match &scan.tail {
            Tail::Clean => {}
            Tail::Torn { bytes } => {
                let cut = cut_back(&path, scan.good_bytes, is_current, &mut state);
                warnings.push(format!(
                    "{}: dropped an incomplete last record of {bytes} bytes (a crash while it was written; it was never acknowledged){cut}",
                    path.display()
                ));
            }
            Tail::Corrupt { reason, .. } => {
                let kept = copy_aside(&path);
                let cut = cut_back(&path, scan.good_bytes, is_current, &mut state);
                warnings.push(format!(
                    "{} is corrupt: {reason}; the records after it are lost ({kept}){cut}",
                    path.display()
                ));
                recovered.rewrite = true;
            }
        }
        if is_current {
            state.log_bytes = scan.good_bytes;
            state.log_records = scan.records.len() as u64;
        }
        records.extend(scan.records);
    }
    for record in &records {
        recovered.highest_seen = recovered.highest_seen.max(record.version);
    }

    let Some(Snapshot {
        layer: mut content,
        mut derivation,
        ..
    }) = base
    else {
        return (recovered, state);
    };
    for record in records {
        if record.version <= content.version {
            continue;
        }
        if record.version != content.version + 1 {
            warnings.push(format!(
                "layer '{name}': the changes that made versions {} to {} are in no file; the log goes on from version {}",
                content.version + 1,
                record.version - 1,
                record.version
            ));
            recovered.rewrite = true;
            break;
        }
        if let Err(e) = record.edits.check(&content) {
            warnings.push(format!(
                "{}: the record of version {} does not fit the layer ({}); the records from it on are not used",
                dir.log_path_of(name).display(),
                record.version,
                e.short()
            ));
            recovered.rewrite = true;
            break;
        }
        record.edits.apply(&content.meta, &mut content.cells);
        content.version = record.version;
        if let Some(d) = &mut derivation {
            d.source_version = record.source_version;
        }
    }
    recovered.highest_seen = recovered.highest_seen.max(content.version);
    recovered.layer = Some((content, derivation));
    (recovered, state)
}

/// The current snapshot, or the last verified copy when the current one cannot be read.
fn base_snapshot(
    dir: &DataDir,
    name: &str,
    recovered: &mut Recovered,
    state: &mut LogState,
    warnings: &mut Vec<String>,
) -> Option<Snapshot> {
    let path = dir.path_of(name);
    let prev = dir.path_with(name, ".layer.prev");
    if path.exists() {
        match snapshot::read(&path, name, dir.max_layer_cells) {
            Ok(s) => {
                state.snapshot_bytes = s.file_bytes;
                return Some(s);
            }
            Err(u) => {
                recovered.highest_seen = recovered.highest_seen.max(u.version_seen.unwrap_or(0));
                warnings.push(format!("{}; {}", u.error, move_aside(&path)));
            }
        }
    }
    recovered.rewrite = true;
    // Appends must not go on from a snapshot that is not there.
    state.needs_snapshot = true;
    if !prev.exists() {
        return None;
    }
    match snapshot::read(&prev, name, dir.max_layer_cells) {
        Ok(s) => {
            warnings.push(format!(
                "layer '{name}' restored from the last good copy {} (version {}) and its logs",
                prev.display(),
                s.layer.version
            ));
            Some(s)
        }
        Err(u) => {
            recovered.highest_seen = recovered.highest_seen.max(u.version_seen.unwrap_or(0));
            warnings.push(format!("{}; {}", u.error, move_aside(&prev)));
            None
        }
    }
}

/// Moves a bad file to `<file>.corrupt` (replacing an older one), so nothing is lost
/// and the next start does not read it again.
fn move_aside(path: &Path) -> String {
    let aside = corrupt_path(path);
    match fs::rename(path, &aside) {
        Ok(()) => format!("kept as {}", aside.display()),
        Err(e) => format!("could not move it aside ({e})"),
    }
}

fn copy_aside(path: &Path) -> String {
    let aside = corrupt_path(path);
    match fs::copy(path, &aside) {
        Ok(_) => format!("the whole log is kept as {}", aside.display()),
        Err(e) => format!("it could not be copied aside ({e})"),
    }
}

fn corrupt_path(path: &Path) -> std::path::PathBuf {
    let mut name = path.as_os_str().to_owned();
    name.push(".corrupt");
    name.into()
}

/// Cuts a log back to its good records, so appends go on after them; an empty result
/// is removed. When that fails, the current log must not be appended to again.
fn cut_back(path: &Path, good_bytes: u64, is_current: bool, state: &mut LogState) -> String {
    let outcome = if good_bytes == 0 {
        fs::remove_file(path).map_err(|e| e.to_string())
    } else {
        log::truncate(path, good_bytes).map_err(|e| e.to_string())
    };
    match outcome {
        Ok(()) => String::new(),
        Err(e) => {
            state.needs_snapshot |= is_current;
            format!("; cutting it back failed ({e})")
        }
    }
}

// The data dir's entry point to recovery.
impl DataDir {
    /// Loads every layer. Never fails as a whole: each problem becomes a warning. Files
    /// of a deleted layer (a crash during its deletion) are removed.
    pub fn load_all(&mut self) -> Loaded {
        load_all(self)
    }
}
