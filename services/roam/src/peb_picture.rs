//! Pictures of a PEB field: where localization is good.
//!
//! Each cell is coloured by its position error bound: green at 0 m through yellow to
//! red at [`RED_AT_M`] and beyond; cells with an unbounded PEB (too few anchors in
//! range) are grey. North is up.

use image::{Rgb, RgbImage};
use roam_proto::map::GridMeta;

/// Cells no anchor constellation can localize in.
pub const UNCOVERED: Rgb<u8> = Rgb([150, 150, 160]);
/// The PEB drawn in full red, metres.
pub const RED_AT_M: f32 = 2.0;

/// The colour of one PEB value.
pub fn colour(peb: f32) -> Rgb<u8> {
    if !peb.is_finite() {
        return UNCOVERED;
    }
    let t = (peb / RED_AT_M).clamp(0.0, 1.0);
    // Green → yellow → red.
    let (r, g) = if t < 0.5 {
        (2.0 * t, 1.0)
    } else {
        (1.0, 2.0 * (1.0 - t))
    };
    Rgb([(r * 230.0).round() as u8, (g * 200.0).round() as u8, 40])
}

/// Draws a row-major PEB field (row 0 at the origin), `scale` pixels per cell.
pub fn render(meta: &GridMeta, peb: &[f32], scale: u32) -> RgbImage {
    let scale = scale.max(1);
    let (w, h) = (meta.width, meta.height);
    let mut image = RgbImage::new(w * scale, h * scale);
    for y in 0..h {
        for x in 0..w {
            let value = peb
                .get((y * w + x) as usize)
                .copied()
                .unwrap_or(f32::INFINITY);
            let c = colour(value);
            let top = (h - 1 - y) * scale;
            for dy in 0..scale {
                for dx in 0..scale {
                    image.put_pixel(x * scale + dx, top + dy, c);
                }
            }
        }
    }
    image
}
