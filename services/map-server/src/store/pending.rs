//! A staged change: the new version of every layer it touches, held until it is
//! persisted and installed together (staged in `stage`, committed in `commit`).

use roam_proto::map::{GridMeta, Layer};

use crate::derived::Derivation;
use crate::edits::CellEdits;

/// What a change does to one layer.
#[derive(Debug)]
pub(crate) enum Change {
    /// The whole new layer (its version is the staged one).
    Full(Layer),
    /// Cells written into the current layer.
    Edits(CellEdits),
}

/// One layer's staged change.
#[derive(Debug)]
pub(crate) struct Staged {
    pub name: String,
    pub version: u64,
    pub derivation: Option<Derivation>,
    pub change: Change,
}

/// Layers staged by one change, persisted and installed together.
#[derive(Debug, Default)]
pub(crate) struct Pending {
    pub staged: Vec<Staged>,
}

impl Pending {
    pub fn put(&mut self, staged: Staged) {
        self.staged.retain(|s| s.name != staged.name);
        self.staged.push(staged);
    }

    pub fn meta_of(&self, name: &str) -> Option<GridMeta> {
        self.staged
            .iter()
            .find(|s| s.name == name)
            .and_then(|s| match &s.change {
                Change::Full(layer) => Some(layer.meta),
                Change::Edits(_) => None,
            })
    }

    pub fn version_of(&self, name: &str) -> Option<u64> {
        self.staged
            .iter()
            .find(|s| s.name == name)
            .map(|s| s.version)
    }
}
