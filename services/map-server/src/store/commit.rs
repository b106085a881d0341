//! Committing a staged change: persist every layer of it, then install them together,
//! then compact logs that have outgrown their snapshots.
//!
//! Persisting comes first, so nothing is visible (or acknowledged) that a restart would
//! lose. When one layer of a change cannot be persisted, what was already written for
//! the others is undone (a log append is cut off again; a snapshot is written back from
//! the installed layer), so the files never hold a change the server refused.

use std::sync::Arc;

use super::pending::{Change, Pending, Staged};
use super::publication::{self, Publication};
use super::{LayerStore, StoreError};

impl LayerStore {
    /// Persists then installs the staged layers; returns how each is published.
    pub(super) fn commit(&mut self, pending: Pending) -> Result<Vec<Publication>, StoreError> {
        self.persist(&pending)?;
        let names: Vec<String> = pending.staged.iter().map(|s| s.name.clone()).collect();
        let mut appended = Vec::new();
        let mut publications = Vec::with_capacity(pending.staged.len());
        for staged in pending.staged {
            let publication = match (&staged.change, self.layers.get(&staged.name)) {
                (Change::Edits(edits), Some(current)) => {
                    appended.push(staged.name.clone());
                    publication::of_edits(current, staged.version, edits)
                }
                _ => Publication::Whole(staged.name.clone()),
            };
            publications.push(publication);
            self.install(staged);
        }
        self.forget_tombstones_of(&names);
        for name in appended {
            self.compact_if_due(&name);
        }
        Ok(publications)
    }

    fn persist(&mut self, pending: &Pending) -> Result<(), StoreError> {
        let Some(data) = &mut self.data else {
            return Ok(());
        };
        let mut warnings = Vec::new();
        let mut failure = None;
        let mut written: Vec<&Staged> = Vec::new();
        for staged in &pending.staged {
            let outcome = match &staged.change {
                Change::Full(layer) => data
                    .snapshot(layer, staged.derivation.as_ref())
                    .map(|w| warnings.extend(w)),
                Change::Edits(edits) => data.append(
                    &staged.name,
                    staged.version,
                    staged.derivation.map_or(0, |d| d.source_version),
                    edits,
                ),
            };
            match outcome {
                Ok(()) => written.push(staged),
                Err(e) => {
                    failure = Some(e);
                    break;
                }
            }
        }
        if let Some(e) = failure {
            for staged in written {
                match &staged.change {
                    Change::Edits(_) => data.rollback(&staged.name),
                    Change::Full(_) => {
                        let restored = match self.layers.get(&staged.name) {
                            Some(layer) => data
                                .snapshot(layer, self.derivations.get(&staged.name))
                                .map(|w| warnings.extend(w)),
                            None => data.discard(&staged.name),
                        };
                        if let Err(e) = restored {
                            tracing::error!(
                                "{e}; the next change of '{}' writes a snapshot",
                                staged.name
                            );
                            data.require_snapshot(&staged.name);
                        }
                    }
                }
            }
            for w in warnings {
                self.warn(w);
            }
            return Err(e.into());
        }
        for w in warnings {
            self.warn(w);
        }
        Ok(())
    }

    fn install(&mut self, staged: Staged) {
        match staged.change {
            Change::Full(layer) => {
                self.layers.insert(staged.name.clone(), Arc::new(layer));
            }
            Change::Edits(edits) => {
                if let Some(shared) = self.layers.get_mut(&staged.name) {
                    let layer = Arc::make_mut(shared);
                    edits.apply(&layer.meta, &mut layer.cells);
                    layer.version = staged.version;
                }
            }
        }
        match staged.derivation {
            Some(d) => {
                self.derivations.insert(staged.name, d);
            }
            None => {
                self.derivations.remove(&staged.name);
            }
        }
    }

    /// A layer created again no longer needs its deleted namesake's version.
    fn forget_tombstones_of(&mut self, names: &[String]) {
        let before = self.tombstones.len();
        self.tombstones.retain(|t| !names.contains(&t.name));
        if self.tombstones.len() == before {
            return;
        }
        if let Some(data) = &self.data {
            if let Err(e) = data.save_tombstones(&self.tombstones) {
                // The new layers are safe; at worst a restart keeps a stale tombstone,
                // which a layer of a higher version overrides.
                tracing::warn!("{e}");
            }
        }
    }

    /// Writes a fresh snapshot of `name` when its log has outgrown the last one. The
    /// change is already durable in the log, so a failure here only costs disk.
    fn compact_if_due(&mut self, name: &str) {
        let Some(data) = &mut self.data else {
            return;
        };
        if !data.should_compact(name) {
            return;
        }
        let Some(layer) = self.layers.get(name).cloned() else {
            return;
        };
        let outcome = data.snapshot(&layer, self.derivations.get(name));
        match outcome {
            Ok(warnings) => {
                for w in warnings {
                    self.warn(w);
                }
            }
            Err(e) => self.warn(format!(
                "compacting the log of '{name}' failed ({e}); its log keeps growing until a compaction succeeds"
            )),
        }
    }
}
