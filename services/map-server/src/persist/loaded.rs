//! What loading the data directory found: each layer as its files gave it, the
//! tombstones and the warnings.

use roam_proto::map::Layer;

use super::tombstones::Tombstone;
use crate::derived::Derivation;

/// What loading the data directory found.
#[derive(Debug, Default)]
pub struct Loaded {
    pub layers: Vec<Recovered>,
    /// Deleted layers and their last versions.
    pub tombstones: Vec<Tombstone>,
    /// One sentence per problem: corrupt files, fallbacks, torn records.
    pub warnings: Vec<String>,
    /// Whether any layer file was there at all, readable or not.
    pub found: bool,
}

/// What the files of one layer gave.
#[derive(Debug, Clone, PartialEq)]
pub struct Recovered {
    pub name: String,
    /// The newest content the files hold, with its derivation; `None` when no copy of
    /// the layer could be read.
    pub layer: Option<(Layer, Option<Derivation>)>,
    /// The highest version any readable header or record showed: above `layer`'s own
    /// version when acknowledged changes could not be recovered.
    pub highest_seen: u64,
    /// Whether the files are not what a clean run leaves (a fallback, a repaired log),
    /// so a fresh snapshot should be written.
    pub rewrite: bool,
}
