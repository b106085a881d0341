//! Pictures of layers: what a person looks at instead of reading cell values.
//!
//! North is up: grid row 0 (the origin) is the bottom row of the picture.

use image::{Rgb, RgbImage};

use crate::grid::{occupancy, Grid};

pub const OCCUPIED: Rgb<u8> = Rgb([20, 20, 20]);
pub const UNKNOWN: Rgb<u8> = Rgb([150, 150, 160]);
pub const FREE: Rgb<u8> = Rgb([255, 255, 255]);
/// The colour of information score 100; lower scores blend from white toward it.
pub const INFORMATION: Rgb<u8> = Rgb([240, 120, 0]);

/// Draws occupancy, with the information map tinted over free cells, `scale` pixels
/// per cell.
pub fn render_map(
    occupancy_grid: &Grid<i8>,
    information: Option<&Grid<u8>>,
    scale: u32,
) -> RgbImage {
    let scale = scale.max(1);
    let (w, h) = (occupancy_grid.meta.width, occupancy_grid.meta.height);
    let same_size = information.filter(|i| i.meta.width == w && i.meta.height == h);
    let mut image = RgbImage::new(w * scale, h * scale);
    for y in 0..h as usize {
        for x in 0..w as usize {
            let i = y * w as usize + x;
            let colour = match occupancy_grid.cells[i] {
                occupancy::UNKNOWN => UNKNOWN,
                c if c >= 65 => OCCUPIED,
                _ => match same_size {
                    Some(info) => blend(FREE, INFORMATION, f32::from(info.cells[i]) / 100.0),
                    None => FREE,
                },
            };
            let top = (h as usize - 1 - y) as u32 * scale;
            for dy in 0..scale {
                for dx in 0..scale {
                    image.put_pixel(x as u32 * scale + dx, top + dy, colour);
                }
            }
        }
    }
    image
}

/// The pixel (top-left of the cell's square) where cell (x, y) is drawn.
pub fn pixel_of(occupancy_grid: &Grid<i8>, x: usize, y: usize, scale: u32) -> (u32, u32) {
    let h = occupancy_grid.meta.height as usize;
    (x as u32 * scale, (h - 1 - y) as u32 * scale)
}

fn blend(a: Rgb<u8>, b: Rgb<u8>, t: f32) -> Rgb<u8> {
    let t = t.clamp(0.0, 1.0);
    Rgb(std::array::from_fn(|k| {
        (f32::from(a.0[k]) * (1.0 - t) + f32::from(b.0[k]) * t).round() as u8
    }))
}

/// Colour of a planned path.
pub const PATH: Rgb<u8> = Rgb([0, 90, 220]);
/// Colour of a second path (a baseline) drawn for comparison.
pub const BASELINE: Rgb<u8> = Rgb([200, 0, 160]);
/// Colour of the start and goal markers.
pub const MARKER: Rgb<u8> = Rgb([0, 170, 60]);

/// Draws a path of grid cells `[x, y]` over a picture from [`render_map`] (same
/// `scale` and grid height): each cell filled in the middle, consecutive cells joined.
pub fn draw_path(
    image: &mut RgbImage,
    grid_height: u32,
    cells: &[[u32; 2]],
    scale: u32,
    colour: Rgb<u8>,
) {
    let scale = scale.max(1);
    let centre = |c: [u32; 2]| -> (f64, f64) {
        let top = (grid_height.saturating_sub(1).saturating_sub(c[1])) * scale;
        (
            f64::from(c[0] * scale) + f64::from(scale) / 2.0,
            f64::from(top) + f64::from(scale) / 2.0,
        )
    };
    let thickness = (scale / 3).max(1) as i64;
    let mut dot = |x: f64, y: f64| {
        for dy in -thickness / 2..=thickness / 2 {
            for dx in -thickness / 2..=thickness / 2 {
                let (px, py) = (x as i64 + dx, y as i64 + dy);
                if px >= 0 && py >= 0 && (px as u32) < image.width() && (py as u32) < image.height()
                {
                    image.put_pixel(px as u32, py as u32, colour);
                }
            }
        }
    };
    for pair in cells.windows(2) {
        let (a, b) = (centre(pair[0]), centre(pair[1]));
        let steps = (f64::from(scale) * 2.0).ceil() as usize;
        for k in 0..=steps {
            let t = k as f64 / steps as f64;
            dot(a.0 + (b.0 - a.0) * t, a.1 + (b.1 - a.1) * t);
        }
    }
    if let [only] = cells {
        let (x, y) = centre(*only);
        dot(x, y);
    }
}

/// Marks a cell with a filled square of `colour`, the cell's size plus a border.
pub fn draw_marker(
    image: &mut RgbImage,
    grid_height: u32,
    cell: [u32; 2],
    scale: u32,
    colour: Rgb<u8>,
) {
    let scale = scale.max(1);
    let top = (grid_height.saturating_sub(1).saturating_sub(cell[1])) * scale;
    let left = cell[0] * scale;
    let border = scale;
    for y in top.saturating_sub(border)..(top + scale + border).min(image.height()) {
        for x in left.saturating_sub(border)..(left + scale + border).min(image.width()) {
            image.put_pixel(x, y, colour);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use roam_proto::map::{GridMeta, Origin};

    #[test]
    fn cells_are_drawn_north_up_with_information_tint() {
        let meta = GridMeta {
            width: 3,
            height: 2,
            resolution: 1.0,
            origin: Origin::default(),
        };
        let mut occ = Grid::filled(meta, occupancy::FREE);
        occ.cells[0] = occupancy::OCCUPIED; // (0, 0): bottom-left
        occ.cells[5] = occupancy::UNKNOWN; // (2, 1): top-right
        let mut info = Grid::filled(meta, 0u8);
        info.cells[1] = 100; // (1, 0)
        let image = render_map(&occ, Some(&info), 2);
        assert_eq!(image.dimensions(), (6, 4));
        assert_eq!(*image.get_pixel(0, 3), OCCUPIED);
        assert_eq!(*image.get_pixel(5, 0), UNKNOWN);
        assert_eq!(*image.get_pixel(2, 2), INFORMATION);
        assert_eq!(*image.get_pixel(0, 0), FREE);
        assert_eq!(pixel_of(&occ, 1, 0, 2), (2, 2));
    }
}
