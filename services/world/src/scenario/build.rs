//! Building a scenario's grids: the occupancy of a `grid:` map and the information map.

use std::path::Path;

use roam_proto::map::{GridMeta, Origin};

use super::file::{GridSpec, InformationSpec};
use crate::grid::{cell_center, occupancy, Grid};
use crate::load_dirs::Access;

pub(crate) fn build_grid(spec: &GridSpec, max_cells: u64) -> Result<Grid<i8>, String> {
    let [wm, hm] = spec.size_m;
    if !(spec.resolution.is_finite() && spec.resolution > 0.0) {
        return Err(format!(
            "resolution must be a positive number of metres per cell, got {}",
            spec.resolution
        ));
    }
    if !(wm.is_finite() && hm.is_finite() && wm > 0.0 && hm > 0.0) {
        return Err(format!(
            "size_m must be two positive numbers, got [{wm}, {hm}]"
        ));
    }
    let (w, h) = (
        (wm / spec.resolution).round(),
        (hm / spec.resolution).round(),
    );
    if w * h > max_cells as f64 {
        return Err(format!(
            "the grid has {} cells; the limit max_layer_cells is {max_cells}",
            w * h
        ));
    }
    let meta = GridMeta {
        width: w as u32,
        height: h as u32,
        resolution: spec.resolution,
        origin: Origin {
            x: spec.origin[0],
            y: spec.origin[1],
            yaw: 0.0,
        },
    };
    let mut grid = Grid::filled(meta, occupancy::FREE);
    let (w, h) = (grid.width(), grid.height());
    for y in 0..h {
        for x in 0..w {
            let border = spec.border_walls && (x == 0 || y == 0 || x == w - 1 || y == h - 1);
            let (cx, cy) = cell_center(&meta, x, y);
            if border || spec.obstacles.iter().any(|s| s.contains(cx, cy)) {
                grid.cells[y * w + x] = occupancy::OCCUPIED;
            }
        }
    }
    Ok(grid)
}

pub(crate) fn build_information(
    spec: &InformationSpec,
    meta: &GridMeta,
    base: &Path,
    max_cells: u64,
    access: Access<'_>,
) -> Result<Grid<u8>, (String, String)> {
    if spec.default_score > 100 {
        return Err((
            "information.default_score".into(),
            format!("scores are 0..=100, got {}", spec.default_score),
        ));
    }
    let mut grid = Grid::filled(*meta, spec.default_score);
    if let Some(image) = &spec.image {
        let field = "information.image".to_owned();
        let image_path = access
            .check(&base.join(image))
            .map_err(|refused| (field.clone(), refused.to_string()))?;
        let fail = |reason: String| (field.clone(), format!("{}: {reason}", image_path.display()));
        let bytes = crate::ros_map::read_bounded(&image_path).map_err(|e| fail(e.to_string()))?;
        let decoded = image::load_from_memory(&bytes)
            .map_err(|e| fail(e.to_string()))?
            .to_luma8();
        if (decoded.width(), decoded.height()) != (meta.width, meta.height) {
            return Err(fail(format!(
                "the image is {}x{} but the map is {}x{}",
                decoded.width(),
                decoded.height(),
                meta.width,
                meta.height
            )));
        }
        if u64::from(decoded.width()) * u64::from(decoded.height()) > max_cells {
            return Err(fail(format!(
                "more than max_layer_cells = {max_cells} cells"
            )));
        }
        let h = meta.height as usize;
        for (x, y, p) in decoded.enumerate_pixels() {
            let row = h - 1 - y as usize;
            grid.cells[row * meta.width as usize + x as usize] =
                ((f64::from(p.0[0]) * 100.0 / 255.0).round()) as u8;
        }
    }
    for (i, zone) in spec.zones.iter().enumerate() {
        if zone.score > 100 {
            return Err((
                format!("information.zones[{i}].score"),
                format!(
                    "zone '{}': scores are 0..=100, got {}",
                    zone.name, zone.score
                ),
            ));
        }
        let shape = zone.shape().ok_or_else(|| {
            (
                format!("information.zones[{i}]"),
                format!("zone '{}' needs exactly one of rect or circle", zone.name),
            )
        })?;
        let (w, h) = (grid.width(), grid.height());
        for y in 0..h {
            for x in 0..w {
                let (cx, cy) = cell_center(meta, x, y);
                if shape.contains(cx, cy) {
                    grid.cells[y * w + x] = zone.score;
                }
            }
        }
    }
    Ok(grid)
}
