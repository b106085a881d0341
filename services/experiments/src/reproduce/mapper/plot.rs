//! The reproduction's figure, laid out like paper 004's Fig. 3: the world with the
//! blocks' paths (left), the rate-estimate error over time (middle) and the map quality
//! over time (right), framed with a title (what, which seed and sizes) and a legend
//! (`roam_world::legend`). The axes start at 0 (each axis's end value is written at
//! it), time runs to the last sample, the error axis to the largest mean error, the
//! quality axis to 1; light grid lines mark quarters.
//!
//! Colours: curious [`CURIOUS`] red, the uniform mix [`UNIFORM`] grey, recency
//! [`RECENCY`] blue, Poisson [`POISSON`] green (drawn in that order reversed, so curious
//! is on top and the uniform mix, its baseline, right under it); the blocks' cells and
//! paths in [`BLOCK_PATHS`] (amber for the first block, purple for the second), the
//! robots' starts in [`START`] (magenta), walls near-black.

use std::path::{Path, PathBuf};

use image::{Rgb, RgbImage};
use roam_sim::world::World;
use roam_world::font::{draw_text, text_width};
use roam_world::legend::{framed, Entry, Frame};
use roam_world::scenario::{is_blocked, Scenario};

use crate::reproduce::mapper::experiment::{MappingError, Reproduction};
use roam_mapper::learner::Mode;

pub const CURIOUS: Rgb<u8> = Rgb([215, 40, 40]);
pub const RECENCY: Rgb<u8> = Rgb([40, 90, 220]);
pub const POISSON: Rgb<u8> = Rgb([20, 150, 60]);
pub const UNIFORM: Rgb<u8> = Rgb([125, 125, 125]);
/// One colour per block, in the scenario's order (repeating after four).
pub const BLOCK_PATHS: [Rgb<u8>; 4] = [
    Rgb([240, 170, 0]),
    Rgb([160, 70, 210]),
    Rgb([0, 170, 170]),
    Rgb([150, 100, 50]),
];
pub const START: Rgb<u8> = Rgb([230, 0, 160]);
pub const WALL: Rgb<u8> = Rgb([25, 25, 25]);
pub const BACKGROUND: Rgb<u8> = Rgb([255, 255, 255]);
const AXIS: Rgb<u8> = Rgb([70, 70, 70]);
const GRID: Rgb<u8> = Rgb([222, 222, 222]);

/// The figure's file name in the output folder.
pub const FIGURE_FILE: &str = "mapper_fig3.png";

/// Panel size of the two curve panels, pixels.
pub const CURVE_PANEL: (u32, u32) = (420, 300);
const MARGIN: u32 = 12;

/// A mode's colour.
pub fn colour(mode: Mode) -> Rgb<u8> {
    match mode {
        Mode::Curious => CURIOUS,
        Mode::RecencyOnly => RECENCY,
        Mode::PoissonOnly => POISSON,
        Mode::Uniform => UNIFORM,
    }
}

/// A panel's place in the figure, pixels.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Panel {
    pub x: u32,
    pub y: u32,
    pub width: u32,
    pub height: u32,
}

/// Where the world, error and quality panels sit in the figure of `scenario`.
pub fn layout(scenario: &Scenario) -> [Panel; 3] {
    let (cw, ch) = CURVE_PANEL;
    let (ww, wh) = world_panel_size(scenario, ch);
    let world = Panel {
        x: MARGIN,
        y: MARGIN + (ch.saturating_sub(wh)) / 2,
        width: ww,
        height: wh,
    };
    let error = Panel {
        x: world.x + ww + MARGIN,
        y: MARGIN,
        width: cw,
        height: ch,
    };
    let quality = Panel {
        x: error.x + cw + MARGIN,
        ..error
    };
    [world, error, quality]
}

/// The three panels side by side, as [`layout`] places them.
pub fn figure(scenario: &Scenario, r: &Reproduction) -> RgbImage {
    let (cw, ch) = CURVE_PANEL;
    let mut series_error = Vec::new();
    let mut series_quality = Vec::new();
    // Curious last, so on top.
    for mode in [
        Mode::PoissonOnly,
        Mode::RecencyOnly,
        Mode::Uniform,
        Mode::Curious,
    ] {
        if let Some(c) = r.curves.iter().find(|c| c.name == mode.as_str()) {
            series_error.push((colour(mode), c.rate_error.as_slice()));
            series_quality.push((colour(mode), c.map_quality.as_slice()));
        }
    }
    let error_max = series_error
        .iter()
        .flat_map(|(_, v)| v.iter().copied())
        .filter(|v| v.is_finite())
        .fold(0.0, f64::max);
    let panels = [
        world_panel(scenario, ch),
        curve_panel(&r.time_s, &series_error, error_max * 1.05, cw, ch),
        curve_panel(&r.time_s, &series_quality, 1.0, cw, ch),
    ];
    let places = layout(scenario);
    let (width, height) = figure_size(scenario);
    let mut out = RgbImage::from_pixel(width, height, BACKGROUND);
    for (panel, place) in panels.iter().zip(places) {
        paste(&mut out, panel, place.x, place.y);
    }
    out
}

/// The title and legend around [`figure`].
pub fn figure_frame(r: &Reproduction) -> Frame {
    let o = &r.options;
    let mut legend: Vec<Entry> = Mode::ALL
        .iter()
        .map(|&m| Entry::line(colour(m), m.as_str()))
        .collect();
    legend.extend([
        Entry::fill(WALL, "wall"),
        Entry::fill(BLOCK_PATHS[0], "block 1: its path, cells"),
        Entry::fill(BLOCK_PATHS[1], "block 2: its path, cells"),
        Entry::fill(START, "robot's start"),
    ]);
    Frame {
        title: vec![
            format!(
                "paper 004 Fig. 3 on {}: seed {}, runs per strategy {}, {} s each",
                r.scenario, o.seed, o.repetitions, o.steps
            ),
            "left: the world; middle: rate-estimate error; right: map quality".into(),
        ],
        legend,
        text_scale: 1,
        pixels_per_metre: None,
    }
}

/// The panels' places in the written (framed) figure.
pub fn framed_layout(scenario: &Scenario, r: &Reproduction) -> [Panel; 3] {
    let places = layout(scenario);
    let size = figure_size(scenario);
    let (dx, dy) = roam_world::legend::layout(size, &figure_frame(r)).picture;
    places.map(|p| Panel {
        x: p.x + dx,
        y: p.y + dy,
        ..p
    })
}

/// The size of [`figure`]'s image.
fn figure_size(scenario: &Scenario) -> (u32, u32) {
    let (cw, ch) = CURVE_PANEL;
    let places = layout(scenario);
    (
        places[2].x + cw + MARGIN,
        ch.max(places[0].height) + 2 * MARGIN,
    )
}

/// Writes the figure as `FIGURE_FILE` in `out_dir` (created if missing).
pub fn write_figure(
    scenario: &Scenario,
    r: &Reproduction,
    out_dir: &Path,
) -> Result<PathBuf, MappingError> {
    let io = |e: &dyn std::fmt::Display, path: &Path| MappingError::Io {
        path: path.display().to_string(),
        reason: e.to_string(),
    };
    std::fs::create_dir_all(out_dir).map_err(|e| io(&e, out_dir))?;
    let path = out_dir.join(FIGURE_FILE);
    framed(&figure(scenario, r), &figure_frame(r))
        .save(&path)
        .map_err(|e| io(&e, &path))?;
    Ok(path)
}

fn paste(out: &mut RgbImage, panel: &RgbImage, x0: u32, y0: u32) {
    for (x, y, p) in panel.enumerate_pixels() {
        if x0 + x < out.width() && y0 + y < out.height() {
            out.put_pixel(x0 + x, y0 + y, *p);
        }
    }
}

/// Pixels per cell of the world panel.
fn world_scale(scenario: &Scenario, size: u32) -> u32 {
    let m = &scenario.occupancy.meta;
    (size / m.width.max(m.height).max(1)).max(1)
}

fn world_panel_size(scenario: &Scenario, size: u32) -> (u32, u32) {
    let m = &scenario.occupancy.meta;
    let scale = world_scale(scenario, size);
    (m.width.max(1) * scale, m.height.max(1) * scale)
}

/// The world: walls, the cells each block ever covers tinted in its colour, its path
/// through its positions' centres, the robots' starts. About `size` pixels square.
pub fn world_panel(scenario: &Scenario, size: u32) -> RgbImage {
    let grid = &scenario.occupancy;
    let (w, h) = (grid.meta.width.max(1), grid.meta.height.max(1));
    let scale = world_scale(scenario, size);
    let mut img = RgbImage::from_pixel(w * scale, h * scale, BACKGROUND);
    let fill = |img: &mut RgbImage, (x, y): (i64, i64), c: Rgb<u8>| {
        if x < 0 || y < 0 || x >= i64::from(w) || y >= i64::from(h) {
            return;
        }
        let top = (i64::from(h) - 1 - y) as u32 * scale;
        for dy in 0..scale {
            for dx in 0..scale {
                img.put_pixel(x as u32 * scale + dx, top + dy, c);
            }
        }
    };
    for y in 0..h {
        for x in 0..w {
            let v = grid.cells.get((y * w + x) as usize).copied().unwrap_or(-1);
            if is_blocked(v) {
                fill(&mut img, (i64::from(x), i64::from(y)), WALL);
            }
        }
    }
    let centre = |(x, y): (i64, i64)| {
        (
            (x as f64 + 0.5) * f64::from(scale),
            (f64::from(h) - 1.0 - y as f64 + 0.5) * f64::from(scale),
        )
    };
    if let Ok(world) = World::new(scenario, 0) {
        for (k, b) in world.blocks().iter().enumerate() {
            let c = BLOCK_PATHS[k % BLOCK_PATHS.len()];
            let light = Rgb(c.0.map(|v| ((u16::from(v) + 2 * 255) / 3) as u8));
            for &p in &b.path {
                for cell in b.footprint.cells(p) {
                    fill(&mut img, cell, light);
                }
            }
            for pair in b.path.windows(2) {
                line(&mut img, centre(pair[0]), centre(pair[1]), c, 2);
            }
            if let (Some(&first), Some(&last)) = (b.path.first(), b.path.last()) {
                line(&mut img, centre(last), centre(first), c, 2);
            }
        }
    }
    for robot in &scenario.file.robots {
        let cell = roam_world::grid::world_to_cell(&grid.meta, robot.at[0], robot.at[1]);
        if let Some((x, y)) = cell {
            fill(&mut img, (x as i64, y as i64), START);
        }
    }
    img
}

/// Curves over time: x from the first to the last of `time`, y from 0 to `y_max`.
pub fn curve_panel(
    time: &[f64],
    series: &[(Rgb<u8>, &[f64])],
    y_max: f64,
    width: u32,
    height: u32,
) -> RgbImage {
    let mut img = RgbImage::from_pixel(width, height, BACKGROUND);
    let (left, right, top, bottom) = (30.0, 8.0, 8.0, 24.0);
    let (pw, ph) = (
        f64::from(width) - left - right,
        f64::from(height) - top - bottom,
    );
    let (t0, t1) = (
        time.first().copied().unwrap_or(0.0),
        time.last().copied().unwrap_or(1.0),
    );
    let span = if t1 > t0 { t1 - t0 } else { 1.0 };
    let y_max = if y_max.is_finite() && y_max > 0.0 {
        y_max
    } else {
        1.0
    };
    let to_px = |t: f64, v: f64| {
        (
            left + (t - t0) / span * pw,
            top + ph - (v / y_max).clamp(0.0, 1.0) * ph,
        )
    };
    for q in 1..=4 {
        let f = f64::from(q) / 4.0;
        line(
            &mut img,
            (left, top + ph - f * ph),
            (left + pw, top + ph - f * ph),
            GRID,
            1,
        );
        line(
            &mut img,
            (left + f * pw, top),
            (left + f * pw, top + ph),
            GRID,
            1,
        );
    }
    line(&mut img, (left, top), (left, top + ph), AXIS, 2);
    line(&mut img, (left, top + ph), (left + pw, top + ph), AXIS, 2);
    // The axes' end values: 0 and the top value left of the y axis, the last time under
    // the x axis's end.
    let top_value = format!("{y_max:.2}");
    for (text, y) in [("0".to_owned(), top + ph - 3.0), (top_value, top)] {
        let x = left - 4.0 - f64::from(text_width(&text, 1));
        draw_text(&mut img, x.max(0.0) as i64, y as i64, &text, 1, AXIS);
    }
    let end = format!("{:.0} s", t1 - t0);
    let x = left + pw - f64::from(text_width(&end, 1));
    draw_text(&mut img, x as i64, (top + ph + 6.0) as i64, &end, 1, AXIS);
    for &(c, values) in series {
        let points: Vec<(f64, f64)> = time
            .iter()
            .zip(values)
            .filter(|(_, v)| v.is_finite())
            .map(|(&t, &v)| to_px(t, v))
            .collect();
        for pair in points.windows(2) {
            line(&mut img, pair[0], pair[1], c, 2);
        }
    }
    img
}

/// A line `thickness` pixels wide (a square brush), clipped to the image.
fn line(img: &mut RgbImage, a: (f64, f64), b: (f64, f64), c: Rgb<u8>, thickness: u32) {
    let steps = (b.0 - a.0).abs().max((b.1 - a.1).abs()).ceil().max(1.0) as u32;
    let (w, h) = (i64::from(img.width()), i64::from(img.height()));
    let half = i64::from(thickness) / 2;
    for i in 0..=steps {
        let f = f64::from(i) / f64::from(steps);
        let (x, y) = (
            (a.0 + (b.0 - a.0) * f).round() as i64,
            (a.1 + (b.1 - a.1) * f).round() as i64,
        );
        for dy in 0..i64::from(thickness) {
            for dx in 0..i64::from(thickness) {
                let (px, py) = (x + dx - half, y + dy - half);
                if px >= 0 && py >= 0 && px < w && py < h {
                    img.put_pixel(px as u32, py as u32, c);
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The mean row of the pixels of colour `c` in columns [x0, x1).
    fn mean_row(img: &RgbImage, c: Rgb<u8>, x0: u32, x1: u32) -> Option<f64> {
        let (mut n, mut sum) = (0u64, 0u64);
        for (x, y, p) in img.enumerate_pixels() {
            if *p == c && (x0..x1).contains(&x) {
                n += 1;
                sum += u64::from(y);
            }
        }
        (n > 0).then(|| sum as f64 / n as f64)
    }

    #[test]
    fn curves_go_where_their_values_go() {
        let time: Vec<f64> = (0..=100).map(f64::from).collect();
        let falling: Vec<f64> = time.iter().map(|t| 1.0 - t / 100.0).collect();
        let rising: Vec<f64> = time.iter().map(|t| t / 200.0).collect();
        let img = curve_panel(
            &time,
            &[(CURIOUS, &falling), (RECENCY, &rising)],
            1.0,
            400,
            300,
        );
        let (l, r) = ((30, 100), (300, 390));
        let (cl, cr) = (
            mean_row(&img, CURIOUS, l.0, l.1).expect("curious left"),
            mean_row(&img, CURIOUS, r.0, r.1).expect("curious right"),
        );
        assert!(
            cl < cr - 100.0,
            "a falling curve is high on the left: {cl} {cr}"
        );
        let (rl, rr) = (
            mean_row(&img, RECENCY, l.0, l.1).expect("recency left"),
            mean_row(&img, RECENCY, r.0, r.1).expect("recency right"),
        );
        assert!(
            rl > rr + 50.0,
            "a rising curve is low on the left: {rl} {rr}"
        );
        // The rising curve ends at half height: row ≈ 8 + 268/2.
        let end = mean_row(&img, RECENCY, 385, 392).expect("end");
        assert!((end - 142.0).abs() < 4.0, "{end}");
        assert!(mean_row(&img, POISSON, 0, 400).is_none());
    }
}
