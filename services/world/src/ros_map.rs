//! Maps in the ROS `map_server` format (a `map.yaml` and a PGM/PNG image), read and
//! written exactly as Nav2's `nav2_map_server/src/map_io.cpp` does.
//!
//! Reading, per pixel: `shade` is the mean of the colour channels scaled to 0..1 (in
//! trinary mode the alpha channel joins the mean, as Nav2 does for images with alpha);
//! `occ = 1 - shade`, or `shade` when `negate` is set. Then, by mode:
//! - trinary: `occ > occupied_thresh` → 100, `occ < free_thresh` → 0, otherwise -1;
//! - scale: a pixel that is not fully opaque → -1; the same two thresholds; in between
//!   `rint((occ - free) / (occupied - free) * 100)`;
//! - raw: `round(shade * 255)`, kept when it is in 0..=100, otherwise -1 (no negate).
//!
//! Image row 0 is the top of the map; grid row 0 is at the origin, so rows are flipped.

use std::path::{Path, PathBuf};

use roam_proto::excerpt::file_parse_reason;

use crate::load_dirs::{Access, LoadRefused};

use roam_proto::map::{GridMeta, Origin};
use serde::Deserialize;

use crate::grid::{occupancy, Grid};

/// How pixel values become occupancy.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum MapMode {
    Trinary,
    Scale,
    Raw,
}

impl MapMode {
    pub fn as_str(self) -> &'static str {
        match self {
            MapMode::Trinary => "trinary",
            MapMode::Scale => "scale",
            MapMode::Raw => "raw",
        }
    }
}

/// `negate` is an integer in Nav2's files; `true`/`false` are accepted too.
#[derive(Debug, Clone, Copy, Deserialize)]
#[serde(untagged)]
enum Flag {
    Int(i64),
    Bool(bool),
}

/// The fields of a ROS `map.yaml`. Other keys are ignored, as Nav2 ignores them.
#[derive(Debug, Clone, Deserialize)]
struct MapYaml {
    image: String,
    resolution: f64,
    origin: Vec<f64>,
    #[serde(default)]
    mode: Option<MapMode>,
    #[serde(default)]
    negate: Option<Flag>,
    occupied_thresh: f64,
    free_thresh: f64,
}

/// The parameters of a loaded map, as its yaml gave them.
#[derive(Debug, Clone, PartialEq)]
pub struct MapParams {
    pub image: PathBuf,
    pub mode: MapMode,
    pub negate: bool,
    pub occupied_thresh: f64,
    pub free_thresh: f64,
}

/// A loaded ROS map.
#[derive(Debug, Clone, PartialEq)]
pub struct RosMap {
    pub grid: Grid<i8>,
    pub params: MapParams,
}

/// Why a ROS map could not be read or written. Every variant names the file.
#[derive(Debug, thiserror::Error)]
pub enum RosMapError {
    #[error("map file {path} does not exist")]
    Missing { path: PathBuf },
    #[error("cannot read map file {path}: {reason}")]
    Io { path: PathBuf, reason: String },
    #[error("map file {path} is invalid: {reason}")]
    Invalid { path: PathBuf, reason: String },
    #[error("map image {path} cannot be decoded: {reason}")]
    Image { path: PathBuf, reason: String },
    #[error(transparent)]
    Refused(#[from] LoadRefused),
    #[error("map image {path} has {actual} cells; the limit max_layer_cells is {max}")]
    TooLarge {
        path: PathBuf,
        max: u64,
        actual: u64,
    },
}

/// The largest map, image or scenario file read, bytes: far above any real map (a
/// 1.7-million-cell PGM is 1.7 MB), low enough that a wrong path cannot exhaust memory.
pub const MAX_FILE_BYTES: u64 = 256 * 1024 * 1024;

/// Reads a whole file, refusing anything that is not a regular file (a FIFO or a device
/// would block or never end) and files over [`MAX_FILE_BYTES`].
pub fn read_bounded(path: &Path) -> std::io::Result<Vec<u8>> {
    use std::io::Read;
    let meta = std::fs::metadata(path)?;
    if !meta.is_file() {
        return Err(std::io::Error::new(
            std::io::ErrorKind::InvalidInput,
            "not a regular file (a folder, FIFO or device cannot be read whole)",
        ));
    }
    if meta.len() > MAX_FILE_BYTES {
        return Err(std::io::Error::new(
            std::io::ErrorKind::InvalidInput,
            format!(
                "the file has {} bytes; the limit max_file_bytes is {MAX_FILE_BYTES}",
                meta.len()
            ),
        ));
    }
    let mut bytes = Vec::with_capacity(meta.len() as usize);
    std::fs::File::open(path)?
        .take(MAX_FILE_BYTES + 1)
        .read_to_end(&mut bytes)?;
    if bytes.len() as u64 > MAX_FILE_BYTES {
        return Err(std::io::Error::new(
            std::io::ErrorKind::InvalidInput,
            format!("the file grew past the limit max_file_bytes ({MAX_FILE_BYTES})"),
        ));
    }
    Ok(bytes)
}

/// [`read_bounded`] as UTF-8 text.
pub fn read_bounded_text(path: &Path) -> std::io::Result<String> {
    String::from_utf8(read_bounded(path)?)
        .map_err(|e| std::io::Error::new(std::io::ErrorKind::InvalidData, e))
}

fn io_error(path: &Path, e: std::io::Error) -> RosMapError {
    if e.kind() == std::io::ErrorKind::NotFound {
        RosMapError::Missing {
            path: path.to_owned(),
        }
    } else {
        RosMapError::Io {
            path: path.to_owned(),
            reason: e.to_string(),
        }
    }
}

/// Reads a `map.yaml` and its image. The image path is relative to the yaml's folder.
pub fn load(yaml_path: &Path, max_cells: u64) -> Result<RosMap, RosMapError> {
    load_with(yaml_path, max_cells, Access::Anywhere)
}

/// [`load`], reading the image only where `access` allows (a load from the wire: inside
/// the load directories). Parse errors give the position and what was expected, never
/// the file's content ([`file_parse_reason`]).
pub fn load_with(
    yaml_path: &Path,
    max_cells: u64,
    access: Access<'_>,
) -> Result<RosMap, RosMapError> {
    let text = read_bounded_text(yaml_path).map_err(|e| io_error(yaml_path, e))?;
    let invalid = |reason: String| RosMapError::Invalid {
        path: yaml_path.to_owned(),
        reason,
    };
    let yaml: MapYaml =
        serde_yaml_ng::from_str(&text).map_err(|e| invalid(file_parse_reason(&e.to_string())))?;
    if !(yaml.resolution.is_finite() && yaml.resolution > 0.0) {
        return Err(invalid(format!(
            "resolution must be a positive number of metres per cell, got {}",
            yaml.resolution
        )));
    }
    if yaml.origin.len() != 3 || yaml.origin.iter().any(|v| !v.is_finite()) {
        return Err(invalid(
            "origin must be [x, y, yaw] with three finite numbers".into(),
        ));
    }
    for (name, value) in [
        ("free_thresh", yaml.free_thresh),
        ("occupied_thresh", yaml.occupied_thresh),
    ] {
        if !(0.0..=1.0).contains(&value) {
            return Err(invalid(format!(
                "{name} must be between 0 and 1, got {value}"
            )));
        }
    }
    if yaml.free_thresh > yaml.occupied_thresh {
        return Err(invalid(
            "free_thresh must not exceed occupied_thresh".into(),
        ));
    }
    let negate = match yaml.negate {
        None => false,
        Some(Flag::Bool(b)) => b,
        Some(Flag::Int(0)) => false,
        Some(Flag::Int(1)) => true,
        Some(Flag::Int(other)) => {
            return Err(invalid(format!("negate must be 0 or 1, got {other}")))
        }
    };
    let image_path = access.check(
        &yaml_path
            .parent()
            .unwrap_or_else(|| Path::new("."))
            .join(&yaml.image),
    )?;
    let params = MapParams {
        image: image_path,
        mode: yaml.mode.unwrap_or(MapMode::Trinary),
        negate,
        occupied_thresh: yaml.occupied_thresh,
        free_thresh: yaml.free_thresh,
    };
    let origin = Origin {
        x: yaml.origin[0],
        y: yaml.origin[1],
        yaw: yaml.origin[2],
    };
    let grid = load_image(&params, yaml.resolution, origin, max_cells)?;
    Ok(RosMap { grid, params })
}

/// Converts the image into occupancy with Nav2's rules.
fn load_image(
    params: &MapParams,
    resolution: f64,
    origin: Origin,
    max_cells: u64,
) -> Result<Grid<i8>, RosMapError> {
    let path = &params.image;
    let bytes = read_bounded(path).map_err(|e| io_error(path, e))?;
    let image_error = |reason: String| RosMapError::Image {
        path: path.clone(),
        reason,
    };
    let reader = image::ImageReader::new(std::io::Cursor::new(&bytes))
        .with_guessed_format()
        .map_err(|e| image_error(e.to_string()))?;
    let (width, height) = reader
        .into_dimensions()
        .map_err(|e| image_error(e.to_string()))?;
    let cells = u64::from(width) * u64::from(height);
    if cells > max_cells {
        return Err(RosMapError::TooLarge {
            path: path.clone(),
            max: max_cells,
            actual: cells,
        });
    }
    let image = image::ImageReader::new(std::io::Cursor::new(&bytes))
        .with_guessed_format()
        .map_err(|e| image_error(e.to_string()))?
        .decode()
        .map_err(|e| image_error(e.to_string()))?;
    let has_alpha = image.color().has_alpha();
    let rgba = image.to_rgba16();
    let meta = GridMeta {
        width,
        height,
        resolution,
        origin,
    };
    let mut grid = Grid::filled(meta, occupancy::UNKNOWN);
    const MAX: f64 = 65535.0;
    for (x, y, pixel) in rgba.enumerate_pixels() {
        // Grey images arrive with the grey value in r, g and b, as GraphicsMagick
        // gives them to Nav2, so the mean is the same formula for every image.
        let [r, g, b, a] = pixel.0.map(f64::from);
        let shade = if params.mode == MapMode::Trinary && has_alpha {
            (r + g + b + a) / 4.0 / MAX
        } else {
            (r + g + b) / 3.0 / MAX
        };
        let occ = if params.negate { shade } else { 1.0 - shade };
        let value = match params.mode {
            MapMode::Trinary => threshold(occ, params).unwrap_or(occupancy::UNKNOWN),
            MapMode::Scale => {
                if has_alpha && a < MAX {
                    occupancy::UNKNOWN
                } else {
                    threshold(occ, params).unwrap_or_else(|| {
                        let scaled = (occ - params.free_thresh)
                            / (params.occupied_thresh - params.free_thresh)
                            * 100.0;
                        scaled.round_ties_even() as i8
                    })
                }
            }
            MapMode::Raw => {
                let percent = (shade * 255.0).round();
                if (0.0..=100.0).contains(&percent) {
                    percent as i8
                } else {
                    occupancy::UNKNOWN
                }
            }
        };
        let row = height as usize - 1 - y as usize;
        grid.cells[row * width as usize + x as usize] = value;
    }
    Ok(grid)
}

fn threshold(occ: f64, params: &MapParams) -> Option<i8> {
    if params.occupied_thresh < occ {
        Some(occupancy::OCCUPIED)
    } else if occ < params.free_thresh {
        Some(occupancy::FREE)
    } else {
        None
    }
}

/// Cell counts of an occupancy grid: what `roam map inspect` prints.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
pub struct CellCounts {
    /// Cells at 100. In scale and raw modes cells between 1 and 99 are in no count.
    pub occupied: u64,
    pub free: u64,
    pub unknown: u64,
}

/// Counts occupied (100), free (0) and unknown (-1) cells.
pub fn count_cells(grid: &Grid<i8>) -> CellCounts {
    let mut counts = CellCounts {
        occupied: 0,
        free: 0,
        unknown: 0,
    };
    for &c in &grid.cells {
        match c {
            occupancy::OCCUPIED => counts.occupied += 1,
            occupancy::FREE => counts.free += 1,
            occupancy::UNKNOWN => counts.unknown += 1,
            _ => {}
        }
    }
    counts
}

/// How to write a map back. Nav2's `map_saver` defaults to trinary, 0.65 and 0.25, but
/// with free_thresh 0.25 its own unknown pixel (205, occ 0.196) reads back as free.
/// roam writes 0.196 by default so that unknown cells stay unknown after a round trip.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SaveParams {
    pub mode: MapMode,
    pub occupied_thresh: f64,
    pub free_thresh: f64,
}

impl Default for SaveParams {
    fn default() -> Self {
        SaveParams {
            mode: MapMode::Trinary,
            occupied_thresh: 0.65,
            free_thresh: 0.196,
        }
    }
}

/// Writes `grid` as `<stem>.pgm` (P5) and `<stem>.yaml` next to `yaml_path`, as Nav2's
/// `map_saver` does: trinary pixels 254 free / 0 occupied / 205 unknown (free when the
/// value is at most `rint(free_thresh * 100)`, occupied from `rint(occupied_thresh * 100)`);
/// raw pixels the value itself, 255 for unknown. Scale mode needs an alpha channel,
/// which PGM has not, and is refused.
pub fn save(grid: &Grid<i8>, yaml_path: &Path, params: SaveParams) -> Result<(), RosMapError> {
    let free_int = (params.free_thresh * 100.0).round_ties_even() as i16;
    let occupied_int = (params.occupied_thresh * 100.0).round_ties_even() as i16;
    let pixel = |cell: i8| -> Result<u8, RosMapError> {
        let c = i16::from(cell);
        Ok(match params.mode {
            MapMode::Trinary => {
                if !(0..=100).contains(&c) {
                    205
                } else if c <= free_int {
                    254
                } else if occupied_int <= c {
                    0
                } else {
                    205
                }
            }
            MapMode::Raw => {
                if (0..=100).contains(&c) {
                    c as u8
                } else {
                    255
                }
            }
            MapMode::Scale => {
                return Err(RosMapError::Invalid {
                    path: yaml_path.to_owned(),
                    reason: "saving in scale mode needs an alpha channel; save as trinary or raw"
                        .into(),
                })
            }
        })
    };
    let (w, h) = (grid.width(), grid.height());
    let mut pgm = format!(
        "P5\n# CREATOR: roam map_saver {:.3} m/pix\n{w} {h}\n255\n",
        grid.meta.resolution
    )
    .into_bytes();
    pgm.reserve(w * h);
    for image_row in 0..h {
        let row = h - 1 - image_row;
        for x in 0..w {
            pgm.push(pixel(grid.cells[row * w + x])?);
        }
    }
    let stem = yaml_path
        .file_stem()
        .and_then(|s| s.to_str())
        .unwrap_or("map")
        .to_owned();
    let pgm_path = yaml_path.with_file_name(format!("{stem}.pgm"));
    let o = grid.meta.origin;
    let yaml = format!(
        "image: {stem}.pgm\nmode: {}\nresolution: {}\norigin: [{}, {}, {}]\nnegate: 0\noccupied_thresh: {}\nfree_thresh: {}\n\n",
        params.mode.as_str(),
        grid.meta.resolution,
        o.x,
        o.y,
        o.yaw,
        params.occupied_thresh,
        params.free_thresh
    );
    std::fs::write(&pgm_path, pgm).map_err(|e| io_error(&pgm_path, e))?;
    std::fs::write(yaml_path, yaml).map_err(|e| io_error(yaml_path, e))?;
    Ok(())
}
