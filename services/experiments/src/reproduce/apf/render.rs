//! Pictures of the reproduction, each framed with a title (which figure, which seed), a
//! legend ([`SCHEME_COLOURS`] and the map's colours) and, on maps, a scale bar
//! (`roam_world::legend`):
//!
//! - like paper 002's Fig. 2: the ES1 map shaded by how many anchors cover each cell,
//!   the anchors, the waypoints and one trajectory per scheme;
//! - like Fig. 3 (left): the ES2 trajectories for z_is = 0.9 on the ES2 map;
//! - like Fig. 3 (middle, right): steps and distance against z_is, one line per scheme.
//!
//! North is up: the map's row 0 is the picture's bottom row.

use std::path::{Path, PathBuf};

use image::{Rgb, RgbImage};
use roam_world::font::{draw_text, text_height, text_width};
use roam_world::legend::{framed, Entry, Frame};
use roam_world::scenario::is_blocked;

use crate::closed_loop::setup::Setup;
use crate::reproduce::apf::{Es2Row, Reproduction, Trajectory};
use roam_controller::weights::Scheme;

/// Each scheme's colour, with its name for a legend. Fixed is orange and
/// linear red, as in paper 002's Fig. 2.
pub const SCHEME_COLOURS: [(Scheme, Rgb<u8>, &str); 5] = [
    (Scheme::Plain, Rgb([30, 90, 230]), "blue"),
    (Scheme::Fixed, Rgb([255, 140, 0]), "orange"),
    (Scheme::Cutoff, Rgb([0, 150, 60]), "green"),
    (Scheme::Linear, Rgb([220, 0, 0]), "red"),
    (Scheme::Sinusoidal, Rgb([170, 0, 200]), "purple"),
];
/// Anchors: black squares.
pub const ANCHOR: Rgb<u8> = Rgb([0, 0, 0]);
/// Waypoints: cyan squares.
pub const WAYPOINT: Rgb<u8> = Rgb([0, 200, 220]);
/// Walls and other blocked cells.
pub const WALL: Rgb<u8> = Rgb([90, 60, 40]);
/// Free cells by the number of anchors in range: 0, 1, 2, 3 and more. White is "well
/// covered" (paper 002: at least three anchors), darker greys are sparser coverage.
pub const COVERAGE: [Rgb<u8>; 4] = [
    Rgb([150, 150, 150]),
    Rgb([180, 180, 180]),
    Rgb([212, 212, 212]),
    Rgb([255, 255, 255]),
];
/// Chart axes.
pub const AXIS: Rgb<u8> = Rgb([0, 0, 0]);
/// Chart background.
pub const BACKGROUND: Rgb<u8> = Rgb([255, 255, 255]);

/// Pixels per map cell in the map pictures.
pub const MAP_SCALE: u32 = 5;
/// The charts' size, pixels.
pub const CHART_SIZE: (u32, u32) = (400, 300);
/// The charts' margin around the plot area, pixels.
pub const CHART_MARGIN: u32 = 30;

/// The colour of a scheme's lines.
pub fn colour_of(scheme: Scheme) -> Rgb<u8> {
    SCHEME_COLOURS
        .iter()
        .find(|(s, _, _)| *s == scheme)
        .map_or(AXIS, |(_, c, _)| *c)
}

/// Why a picture was not written.
#[derive(Debug, thiserror::Error)]
pub enum RenderError {
    #[error("cannot create {path}: {reason}")]
    Io { path: PathBuf, reason: String },
    #[error("cannot write {path}: {reason}")]
    Encode { path: PathBuf, reason: String },
}

/// A canvas that takes world or chart coordinates and clips whatever falls outside.
struct Canvas<'a> {
    image: &'a mut RgbImage,
}

impl Canvas<'_> {
    fn put(&mut self, x: i64, y: i64, colour: Rgb<u8>) {
        if x >= 0 && y >= 0 && (x as u32) < self.image.width() && (y as u32) < self.image.height() {
            self.image.put_pixel(x as u32, y as u32, colour);
        }
    }

    /// A filled square of side `2 · half + 1` centred on (x, y).
    fn square(&mut self, x: f64, y: f64, half: i64, colour: Rgb<u8>) {
        let (cx, cy) = (x.floor() as i64, y.floor() as i64);
        for dy in -half..=half {
            for dx in -half..=half {
                self.put(cx + dx, cy + dy, colour);
            }
        }
    }

    /// A line `2 · half + 1` pixels thick.
    fn line(&mut self, a: (f64, f64), b: (f64, f64), half: i64, colour: Rgb<u8>) {
        let length = (b.0 - a.0).hypot(b.1 - a.1);
        let samples = (length * 2.0).ceil().max(1.0) as usize;
        for k in 0..=samples {
            let t = k as f64 / samples as f64;
            self.square(a.0 + (b.0 - a.0) * t, a.1 + (b.1 - a.1) * t, half, colour);
        }
    }
}

/// The pixel of world point `p` on a map picture of `setup` at `scale` pixels per cell.
pub fn map_pixel(setup: &Setup, p: [f64; 2], scale: u32) -> (f64, f64) {
    let meta = setup.scenario.occupancy.meta;
    let per_metre = f64::from(scale) / meta.resolution;
    (
        (p[0] - meta.origin.x) * per_metre,
        f64::from(meta.height * scale) - (p[1] - meta.origin.y) * per_metre,
    )
}

/// The map shaded by anchor coverage ([`COVERAGE`]), walls, the anchors and the
/// scenario's waypoints, `scale` pixels per cell.
pub fn render_map(setup: &Setup, scale: u32) -> RgbImage {
    let scale = scale.max(1);
    let grid = &setup.scenario.occupancy;
    let meta = grid.meta;
    let mut image = RgbImage::new(meta.width * scale, meta.height * scale);
    for y in 0..meta.height {
        for x in 0..meta.width {
            let i = (y * meta.width + x) as usize;
            let colour = if grid.cells.get(i).is_none_or(|&v| is_blocked(v)) {
                WALL
            } else {
                let (cx, cy) = roam_world::grid::cell_center(&meta, x as usize, y as usize);
                let n = setup.information.coverage([cx, cy]);
                COVERAGE[n.min(COVERAGE.len() - 1)]
            };
            let top = (meta.height - 1 - y) * scale;
            for dy in 0..scale {
                for dx in 0..scale {
                    image.put_pixel(x * scale + dx, top + dy, colour);
                }
            }
        }
    }
    let mut canvas = Canvas { image: &mut image };
    let half = i64::from(scale);
    for a in &setup.scenario.file.anchors {
        let (px, py) = map_pixel(setup, a.at, scale);
        canvas.square(px, py, half, ANCHOR);
    }
    for w in &setup.scenario.file.waypoints {
        let (px, py) = map_pixel(setup, w.at, scale);
        canvas.square(px, py, half, WAYPOINT);
    }
    image
}

/// Draws true trajectories over a picture from [`render_map`] (same `scale`), each in
/// its scheme's colour, in the order given (later ones on top), about half a cell thick.
pub fn draw_trajectories(
    image: &mut RgbImage,
    setup: &Setup,
    trajectories: &[Trajectory],
    scale: u32,
) {
    let half = i64::from(scale.max(1) / 4);
    let mut canvas = Canvas { image };
    for t in trajectories {
        let colour = colour_of(t.scheme);
        let points: Vec<(f64, f64)> = t
            .truth
            .iter()
            .map(|&p| map_pixel(setup, p, scale))
            .collect();
        for pair in points.windows(2) {
            canvas.line(pair[0], pair[1], half, colour);
        }
        if let [only] = points.as_slice() {
            canvas.square(only.0, only.1, half, colour);
        }
    }
}

/// What an ES2 chart plots against z_is.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Metric {
    /// Mean steps (Fig. 3, middle).
    Steps,
    /// Mean distance (Fig. 3, right).
    Distance,
}

fn value(row: &Es2Row, metric: Metric) -> Option<f64> {
    match metric {
        Metric::Steps => row.steps,
        Metric::Distance => row.distance_m,
    }
}

/// The pixel of (z, value) on a chart whose axes run over [z_min, z_max] × [0, v_max].
pub fn chart_pixel(z: f64, v: f64, z_range: (f64, f64), v_max: f64) -> (f64, f64) {
    let (w, h) = CHART_SIZE;
    let m = f64::from(CHART_MARGIN);
    let (plot_w, plot_h) = (f64::from(w) - 2.0 * m, f64::from(h) - 2.0 * m);
    let zt = if z_range.1 > z_range.0 {
        (z - z_range.0) / (z_range.1 - z_range.0)
    } else {
        0.5
    };
    let vt = if v_max > 0.0 { v / v_max } else { 0.0 };
    (m + zt * plot_w, f64::from(h) - m - vt * plot_h)
}

/// The axes' ranges of a chart of `rows`: z over the rows' z_is, the value from 0 to the
/// largest value (10 % headroom).
pub fn chart_ranges(rows: &[Es2Row], metric: Metric) -> ((f64, f64), f64) {
    let z_min = rows.iter().map(|r| r.z_is).fold(f64::INFINITY, f64::min);
    let z_max = rows
        .iter()
        .map(|r| r.z_is)
        .fold(f64::NEG_INFINITY, f64::max);
    let v_max = rows
        .iter()
        .filter_map(|r| value(r, metric))
        .fold(0.0, f64::max);
    let z = if z_min.is_finite() {
        (z_min, z_max)
    } else {
        (0.0, 1.0)
    };
    (z, v_max * 1.1)
}

/// A line chart of `metric` against z_is, one line per scheme in its colour, each point
/// marked with a small square ([`CHART_SIZE`], axes from 0).
pub fn render_chart(rows: &[Es2Row], metric: Metric) -> RgbImage {
    let (w, h) = CHART_SIZE;
    let mut image = RgbImage::from_pixel(w, h, BACKGROUND);
    let (z_range, v_max) = chart_ranges(rows, metric);
    let mut canvas = Canvas { image: &mut image };
    let m = f64::from(CHART_MARGIN);
    let origin = (m, f64::from(h) - m);
    canvas.line(origin, (f64::from(w) - m, origin.1), 0, AXIS);
    canvas.line(origin, (m, m), 0, AXIS);
    axis_labels(canvas.image, z_range, v_max);
    for (scheme, colour, _) in SCHEME_COLOURS {
        let mut points: Vec<(f64, f64)> = rows
            .iter()
            .filter(|r| r.scheme == scheme)
            .filter_map(|r| value(r, metric).map(|v| (r.z_is, v)))
            .collect();
        points.sort_by(|a, b| a.0.total_cmp(&b.0));
        let pixels: Vec<(f64, f64)> = points
            .iter()
            .map(|&(z, v)| chart_pixel(z, v, z_range, v_max))
            .collect();
        for pair in pixels.windows(2) {
            canvas.line(pair[0], pair[1], 0, colour);
        }
        for p in &pixels {
            canvas.square(p.0, p.1, 2, colour);
        }
    }
    image
}

/// The axes' end values in the margins: z_is under the x axis's ends, 0 and the top
/// value left of the y axis.
fn axis_labels(image: &mut RgbImage, z_range: (f64, f64), v_max: f64) {
    let (w, h) = CHART_SIZE;
    let m = CHART_MARGIN;
    let below = i64::from(h - m + 4);
    for (z, text) in [
        (z_range.0, format!("{:.1}", z_range.0)),
        (z_range.1, format!("{:.1}", z_range.1)),
    ] {
        let (x, _) = chart_pixel(z, 0.0, z_range, v_max);
        let half = i64::from(text_width(&text, 1) / 2);
        draw_text(image, x as i64 - half, below, &text, 1, AXIS);
    }
    let name = "z_is";
    draw_text(
        image,
        i64::from(w / 2) - i64::from(text_width(name, 1) / 2),
        below + i64::from(text_height(1)) + 2,
        name,
        1,
        AXIS,
    );
    for v in [0.0, v_max] {
        let text = format!("{v:.0}");
        let (_, y) = chart_pixel(z_range.0, v, z_range, v_max);
        let x = i64::from(m) - 3 - i64::from(text_width(&text, 1));
        draw_text(image, x.max(0), y as i64 - 3, &text, 1, AXIS);
    }
}

/// The legend of the map pictures: each scheme's trajectory, then the map's colours.
pub fn map_legend() -> Vec<Entry> {
    let mut legend: Vec<Entry> = SCHEME_COLOURS
        .iter()
        .map(|(scheme, colour, _)| Entry::line(*colour, &format!("{} trajectory", scheme.name())))
        .collect();
    legend.extend([
        Entry::fill(ANCHOR, "anchor"),
        Entry::fill(WAYPOINT, "waypoint"),
        Entry::fill(WALL, "wall"),
        Entry::fill(COVERAGE[0], "no anchor in range"),
        Entry::fill(COVERAGE[1], "1 anchor in range"),
        Entry::fill(COVERAGE[2], "2 anchors in range"),
        Entry::fill(COVERAGE[3], "3 or more in range"),
    ]);
    legend
}

/// The legend of a chart of `rows`: the line of each scheme in them.
pub fn chart_legend(rows: &[Es2Row]) -> Vec<Entry> {
    SCHEME_COLOURS
        .iter()
        .filter(|(scheme, _, _)| rows.iter().any(|r| r.scheme == *scheme))
        .map(|(scheme, colour, _)| Entry::line(*colour, scheme.name()))
        .collect()
}

/// The frame of a map picture of `setup` at `scale` pixels per cell.
pub fn map_frame(title: Vec<String>, setup: &Setup, scale: u32) -> Frame {
    let resolution = setup.scenario.occupancy.meta.resolution;
    Frame {
        title,
        legend: map_legend(),
        text_scale: 1,
        pixels_per_metre: Some(f64::from(scale) / resolution),
    }
}

fn save(image: &RgbImage, path: &Path) -> Result<(), RenderError> {
    image.save(path).map_err(|e| RenderError::Encode {
        path: path.to_owned(),
        reason: e.to_string(),
    })
}

/// Writes the four pictures into `dir` (created if missing) and returns their paths:
/// `es1_trajectories.png` (Fig. 2), `es2_trajectories.png` (Fig. 3 left),
/// `es2_steps.png` and `es2_distance.png` (Fig. 3 middle and right); `seed` is the
/// run's base seed, for the titles.
pub fn write_figures(
    reproduction: &Reproduction,
    es1: &Setup,
    es2: &Setup,
    dir: &Path,
    seed: u64,
) -> Result<Vec<PathBuf>, RenderError> {
    std::fs::create_dir_all(dir).map_err(|e| RenderError::Io {
        path: dir.to_owned(),
        reason: e.to_string(),
    })?;
    let mut written = Vec::new();
    for (name, setup, trajectories, title) in [
        (
            "es1_trajectories.png",
            es1,
            &reproduction.es1_trajectories,
            "paper 002 ES1 (Fig. 2): a trajectory per scheme",
        ),
        (
            "es2_trajectories.png",
            es2,
            &reproduction.es2_trajectories,
            "paper 002 ES2 (Fig. 3 left): true positions",
        ),
    ] {
        let mut image = render_map(setup, MAP_SCALE);
        draw_trajectories(&mut image, setup, trajectories, MAP_SCALE);
        let frame = map_frame(vec![title.into(), format!("seed {seed}")], setup, MAP_SCALE);
        let path = dir.join(name);
        save(&framed(&image, &frame), &path)?;
        written.push(path);
    }
    for (name, metric, title) in [
        (
            "es2_steps.png",
            Metric::Steps,
            "ES2: mean steps against z_is",
        ),
        (
            "es2_distance.png",
            Metric::Distance,
            "ES2: mean distance (m) against z_is",
        ),
    ] {
        let frame = Frame {
            title: vec![title.into(), format!("paper 002 Fig. 3, seed {seed}")],
            legend: chart_legend(&reproduction.es2),
            text_scale: 1,
            pixels_per_metre: None,
        };
        let path = dir.join(name);
        save(
            &framed(&render_chart(&reproduction.es2, metric), &frame),
            &path,
        )?;
        written.push(path);
    }
    Ok(written)
}

#[cfg(test)]
mod tests {
    use super::*;
    use roam_world::scenario::parse;

    const ROOM: &str = "
name: room
map:
  grid: { size_m: [20.0, 10.0], resolution: 0.5, border_walls: true }
anchors:
  - { name: a, at: [2.0, 5.0] }
  - { name: b, at: [18.0, 5.0] }
  - { name: c, at: [10.0, 9.0] }
sensing: { range_m: 9.0 }
waypoints:
  - { name: A, at: [4.0, 3.0] }
  - { name: B, at: [16.0, 3.0] }
robots:
  - { name: r, at: [4.0, 3.0] }
";

    fn setup() -> Setup {
        let s = parse(Path::new("room.yaml"), ROOM, 1_000_000).expect("scenario");
        Setup::new(&s).expect("setup")
    }

    fn pixel(image: &RgbImage, p: (f64, f64)) -> Rgb<u8> {
        *image.get_pixel(p.0 as u32, p.1 as u32)
    }

    #[test]
    fn the_map_shows_coverage_anchors_waypoints_and_walls() {
        let s = setup();
        let image = render_map(&s, 4);
        assert_eq!(image.dimensions(), (160, 80));
        for a in &s.scenario.file.anchors {
            assert_eq!(pixel(&image, map_pixel(&s, a.at, 4)), ANCHOR, "{}", a.name);
        }
        for w in &s.scenario.file.waypoints {
            assert_eq!(
                pixel(&image, map_pixel(&s, w.at, 4)),
                WAYPOINT,
                "{}",
                w.name
            );
        }
        // The west wall (x < 0.5 m).
        assert_eq!(pixel(&image, map_pixel(&s, [0.2, 2.0], 4)), WALL);
        // (10, 6): a 8.1 m, b 8.1 m, c 3 m: three anchors, white. (3.5, 1.5): only a
        // (3.8 m); b is 14.9 m and c 10.2 m away: one anchor.
        let expect = |p: [f64; 2], n: usize| {
            assert_eq!(s.information.coverage(p), n);
            assert_eq!(pixel(&image, map_pixel(&s, p, 4)), COVERAGE[n.min(3)]);
        };
        expect([10.0, 6.0], 3);
        expect([3.25, 1.25], 1);
    }

    #[test]
    fn each_trajectory_is_drawn_in_its_schemes_colour() {
        let s = setup();
        let mut image = render_map(&s, 4);
        let line = |scheme, y: f64| Trajectory {
            scheme,
            z_is: 0.8,
            robot: "r".into(),
            success: true,
            truth: (0..=20).map(|k| [5.0 + 0.5 * k as f64, y]).collect(),
        };
        draw_trajectories(
            &mut image,
            &s,
            &[line(Scheme::Fixed, 2.0), line(Scheme::Linear, 7.0)],
            4,
        );
        for x in [5.0, 9.3, 15.0] {
            assert_eq!(
                pixel(&image, map_pixel(&s, [x, 2.0], 4)),
                colour_of(Scheme::Fixed)
            );
            assert_eq!(
                pixel(&image, map_pixel(&s, [x, 7.0], 4)),
                colour_of(Scheme::Linear)
            );
        }
        // Off the lines the map is untouched.
        assert_eq!(pixel(&image, map_pixel(&s, [10.0, 4.5], 4)), COVERAGE[3]);
        // Every scheme has its own colour.
        for (i, a) in SCHEME_COLOURS.iter().enumerate() {
            for b in &SCHEME_COLOURS[i + 1..] {
                assert_ne!(a.1, b.1);
            }
        }
    }

    fn row(scheme: Scheme, z_is: f64, steps: f64) -> Es2Row {
        Es2Row {
            scheme,
            z_is,
            steps: Some(steps),
            distance_m: Some(steps / 5.0),
            success_rate: 1.0,
            rmse_m: None,
            runs: 1,
        }
    }

    #[test]
    fn the_chart_puts_each_point_where_its_value_is() {
        let rows = [
            row(Scheme::Fixed, 0.0, 600.0),
            row(Scheme::Fixed, 0.5, 900.0),
            row(Scheme::Fixed, 0.9, 3000.0),
            row(Scheme::Linear, 0.0, 600.0),
            row(Scheme::Linear, 0.9, 700.0),
        ];
        let image = render_chart(&rows, Metric::Steps);
        assert_eq!(image.dimensions(), CHART_SIZE);
        let (z, v_max) = chart_ranges(&rows, Metric::Steps);
        assert_eq!(z, (0.0, 0.9));
        assert!((v_max - 3300.0).abs() < 1e-9);
        let at = |z_is, v| pixel(&image, chart_pixel(z_is, v, z, v_max));
        assert_eq!(at(0.9, 3000.0), colour_of(Scheme::Fixed));
        assert_eq!(at(0.5, 900.0), colour_of(Scheme::Fixed));
        assert_eq!(at(0.9, 700.0), colour_of(Scheme::Linear));
        // The larger value is higher up.
        assert!(chart_pixel(0.9, 3000.0, z, v_max).1 < chart_pixel(0.9, 700.0, z, v_max).1);
        // Axes at the margin; nothing drawn in the empty top-left of the plot.
        let m = f64::from(CHART_MARGIN);
        assert_eq!(pixel(&image, (m, f64::from(CHART_SIZE.1) - m)), AXIS);
        assert_eq!(pixel(&image, (m + 20.0, m + 5.0)), BACKGROUND);
        let distance = render_chart(&rows, Metric::Distance);
        let (z, v_max) = chart_ranges(&rows, Metric::Distance);
        assert!((v_max - 660.0).abs() < 1e-9);
        assert_eq!(
            pixel(&distance, chart_pixel(0.9, 600.0, z, v_max)),
            colour_of(Scheme::Fixed)
        );
    }

    #[test]
    fn figures_are_written_as_pngs_that_decode() {
        let s = setup();
        let dir =
            std::env::temp_dir().join(format!("roam-controller-render-{}", std::process::id()));
        let r = Reproduction {
            es1: Vec::new(),
            es1_no_guard: Vec::new(),
            es2: vec![
                row(Scheme::Cutoff, 0.0, 600.0),
                row(Scheme::Cutoff, 0.9, 650.0),
            ],
            es3: Vec::new(),
            es1_trajectories: vec![Trajectory {
                scheme: Scheme::Sinusoidal,
                z_is: 0.8,
                robot: "r".into(),
                success: true,
                truth: vec![[4.0, 3.0], [16.0, 3.0]],
            }],
            es2_trajectories: Vec::new(),
        };
        let written = write_figures(&r, &s, &s, &dir, 4).expect("written");
        assert_eq!(written.len(), 4);
        let es1 = image::open(&written[0]).expect("decodes").to_rgb8();
        let (map_w, map_h) = render_map(&s, MAP_SCALE).dimensions();
        let frame = map_frame(vec!["t".into(), "seed 4".into()], &s, MAP_SCALE);
        let layout = roam_world::legend::layout((map_w, map_h), &frame);
        let (left, top) = layout.picture;
        let (x, y) = map_pixel(&s, [10.0, 3.0], MAP_SCALE);
        assert_eq!(
            pixel(&es1, (x + f64::from(left), y + f64::from(top))),
            colour_of(Scheme::Sinusoidal)
        );
        // The legend: each entry's colour at its swatch's centre.
        for (entry, &(x, y, w, h)) in frame.legend.iter().zip(&layout.swatches) {
            assert_eq!(
                *es1.get_pixel(x + w / 2, y + h / 2),
                entry.colour,
                "{}",
                entry.text
            );
        }
        assert!(layout.scale_bar.is_some());
        for path in &written[1..] {
            assert!(image::open(path).is_ok(), "{}", path.display());
        }
        let _ = std::fs::remove_dir_all(&dir);
    }
}
