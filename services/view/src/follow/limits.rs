//! How much the view shows and keeps, and how often it looks.

use std::time::Duration;

use roam_map_server::store::DEFAULT_LIMITS;

/// The most map layers shown (the map server's own default limit, `max_layers`).
pub const MAX_LAYERS: usize = DEFAULT_LIMITS.max_layers as usize;
/// The most cells of one layer shown (the map server's `max_layer_cells`).
pub const MAX_LAYER_CELLS: u64 = DEFAULT_LIMITS.max_layer_cells;
/// The most bytes of grid cells kept for the layers shown, together (their latched
/// messages): nine full-size layers of f32 fit, 64 of them do not.
pub const MAX_LAYER_BYTES_SHOWN: usize = 1 << 30;
/// The largest layer kept as well as shown, bytes of cells, for deltas to apply to (a
/// 1.7-million-cell warehouse map's f32 layers are 6.8 MB); a delta of a larger layer
/// fetches it whole, so the largest layers are not held twice.
pub const MAX_LAYER_BYTES_KEPT: usize = 16 << 20;

/// The most points kept per driven path, and the least distance between two of them.
pub const DRIVEN_POINTS: usize = 4096;
pub const DRIVEN_STEP_M: f64 = 0.05;
/// The driven paths are logged at most this often.
pub const DRIVEN_PERIOD: Duration = Duration::from_millis(250);
/// How often the world loop looks at the layer index and the sim's status.
pub const REFRESH_PERIOD: Duration = roam_runtime::layer_follow::REFRESH_PERIOD;
/// How long one of its queries may take.
pub const QUERY_TIMEOUT: Duration = Duration::from_secs(2);
