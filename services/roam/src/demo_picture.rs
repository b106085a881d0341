//! `world.png` of `roam demo`: the day world with what the robot planned and drove,
//! framed so that the picture explains itself without the report: a title (what, which
//! seed), a legend (each colour), each window's number where the window began, and a
//! scale bar in metres (`roam_world::legend`).

use image::{Rgb, RgbImage};
use roam_mission::executive::WindowOutcome;
use roam_proto::map::GridMeta;
use roam_world::grid::Grid;
use roam_world::legend::{draw_label, label_size, Entry, Frame, Swatch};
use roam_world::render::{
    draw_marker, draw_path, render_map, BASELINE, INFORMATION, MARKER, OCCUPIED, PATH,
};

/// The colour of the path the robot drove (its true positions).
pub const DRIVEN: Rgb<u8> = Rgb([220, 20, 20]);
/// The colour of the anchors.
pub const ANCHOR: Rgb<u8> = roam_sim::render::ANCHOR;
/// The window numbers' ink and border.
pub const WINDOW_LABEL: Rgb<u8> = Rgb([0, 0, 0]);
/// Pixels per cell in the demo's picture of a small world (the built-in day's 100 × 100
/// cells: 800 pixels).
pub const SCALE: u32 = 8;
/// The longer side of the map in the picture, pixels, that a larger world (a user's
/// site) is drawn within, at least one pixel a cell.
pub const PICTURE_SIDE: u32 = 800;
/// The font scale of the window numbers and the legend (14 px letters).
pub const TEXT_SCALE: u32 = 2;
/// Windows that began closer than this, metres, share one label (`3, 4`): a round
/// trip's window begins where the one before it began.
const SAME_PLACE_M: f64 = 1.0;

/// What the picture shows.
#[derive(Debug, Clone, Copy)]
pub struct Day<'a> {
    pub occupancy: &'a Grid<i8>,
    pub information: &'a Grid<u8>,
    pub outcomes: &'a [WindowOutcome],
    /// The robot's true path, world metres.
    pub driven: &'a [[f64; 2]],
    /// The task places, world metres.
    pub tasks: &'a [[f64; 2]],
    pub anchors: &'a [[f64; 2]],
}

/// The grid cell of a world point, clamped onto the map.
pub fn cell_of(meta: &GridMeta, p: [f64; 2]) -> [u32; 2] {
    let x = ((p[0] - meta.origin.x) / meta.resolution).floor();
    let y = ((p[1] - meta.origin.y) / meta.resolution).floor();
    [
        x.clamp(0.0, f64::from(meta.width.saturating_sub(1))) as u32,
        y.clamp(0.0, f64::from(meta.height.saturating_sub(1))) as u32,
    ]
}

/// Pixels per cell for a world of `meta`'s size: [`SCALE`], fewer where the map would
/// pass [`PICTURE_SIDE`].
pub fn picture_scale(meta: &GridMeta) -> u32 {
    (PICTURE_SIDE / meta.width.max(meta.height).max(1)).clamp(1, SCALE)
}

/// The title: what the picture is and which run (ASCII: the built-in font's; `site`
/// is the built-in day or the user's day file's name).
pub fn title(site: &str, seed: u64, rate: f64, windows: usize) -> Vec<String> {
    let world = if site == roam_mission::site::BUILTIN_DAY {
        "the demo's day world".to_owned()
    } else {
        format!("the site {site}")
    };
    let line = |l: String| {
        l.chars()
            .map(|c| if c.is_ascii() { c } else { '?' })
            .collect()
    };
    vec![
        format!("roam demo, seed {seed}: one robot's day, {windows} downtime windows"),
        line(format!(
            "{world}, the sim at {rate}x; numbers: where each window began"
        )),
    ]
}

/// Each colour of the picture and what it means, in the legend's order.
pub fn legend() -> Vec<Entry> {
    vec![
        Entry::fill(INFORMATION, "zone of interest (darker: more)"),
        Entry::fill(OCCUPIED, "wall"),
        Entry::line(PATH, "curious plan"),
        Entry::line(BASELINE, "shortest path"),
        Entry::line(DRIVEN, "driven path"),
        Entry::fill(ANCHOR, "anchor (UWB)"),
        Entry::fill(MARKER, "start and task places"),
        Entry {
            colour: WINDOW_LABEL,
            swatch: Swatch::Label("1".into()),
            text: "window 1 began here".into(),
        },
    ]
}

/// The frame around the map of `meta` drawn at [`picture_scale`].
pub fn frame(site: &str, seed: u64, rate: f64, windows: usize, meta: &GridMeta) -> Frame {
    Frame {
        title: title(site, seed, rate, windows),
        legend: legend(),
        text_scale: TEXT_SCALE,
        pixels_per_metre: Some(f64::from(picture_scale(meta)) / meta.resolution),
    }
}

/// The map with the day on it, unframed: zones of interest, each window's shortest
/// path and plans, the driven path, anchors, the start and task places, and the
/// window numbers.
pub fn draw_day(day: &Day<'_>) -> RgbImage {
    let meta = day.occupancy.meta;
    let cells = |points: &[[f64; 2]]| -> Vec<[u32; 2]> {
        points.iter().map(|p| cell_of(&meta, *p)).collect()
    };
    let scale = picture_scale(&meta);
    let mut image = render_map(day.occupancy, Some(day.information), scale);
    for o in day.outcomes {
        draw_path(
            &mut image,
            meta.height,
            &cells(&o.shortest),
            scale,
            BASELINE,
        );
        for plan in &o.plans {
            draw_path(&mut image, meta.height, &cells(plan), scale, PATH);
        }
    }
    draw_path(&mut image, meta.height, &cells(day.driven), scale, DRIVEN);
    for a in day.anchors {
        draw_marker(&mut image, meta.height, cell_of(&meta, *a), scale, ANCHOR);
    }
    for t in day.tasks {
        draw_marker(&mut image, meta.height, cell_of(&meta, *t), scale, MARKER);
    }
    if let Some(start) = day.driven.first() {
        draw_marker(
            &mut image,
            meta.height,
            cell_of(&meta, *start),
            scale,
            MARKER,
        );
    }
    for (text, at) in window_labels(&window_starts(day.outcomes)) {
        let [x, y] = cell_of(&meta, at);
        let (px, py) = (
            x * scale + scale / 2,
            (meta.height - 1 - y) * scale + scale / 2,
        );
        let (w, h) = label_size(&text, TEXT_SCALE);
        // Up and to the right of the place, clear of its marker, kept on the map.
        let left = (px + 2 * scale).min(image.width().saturating_sub(w));
        let top = py.saturating_sub(2 * scale + h);
        draw_label(&mut image, left, top, &text, TEXT_SCALE, WINDOW_LABEL);
    }
    image
}

/// Each window's number (from 1) and the place it began: its shortest path's first
/// point.
pub fn window_starts(outcomes: &[WindowOutcome]) -> Vec<(usize, [f64; 2])> {
    outcomes
        .iter()
        .filter_map(|o| {
            let began = o
                .shortest
                .first()
                .or_else(|| o.plans.first().and_then(|p| p.first()));
            began.map(|&at| (o.report.window + 1, at))
        })
        .collect()
}

/// One label per place a window began, naming the windows that began there:
/// `("3, 4", place)`.
pub fn window_labels(starts: &[(usize, [f64; 2])]) -> Vec<(String, [f64; 2])> {
    let mut labels: Vec<(Vec<usize>, [f64; 2])> = Vec::new();
    for &(number, at) in starts {
        match labels
            .iter_mut()
            .find(|(_, p)| (p[0] - at[0]).hypot(p[1] - at[1]) < SAME_PLACE_M)
        {
            Some((numbers, _)) => numbers.push(number),
            None => labels.push((vec![number], at)),
        }
    }
    labels
        .into_iter()
        .map(|(numbers, at)| {
            let text: Vec<String> = numbers.iter().map(ToString::to_string).collect();
            (text.join(", "), at)
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn windows_that_began_at_one_place_share_a_label() {
        let starts = [
            (1, [-8.0, -8.0]),
            (2, [-2.0, 4.0]),
            (3, [6.0, -7.0]),
            (4, [6.3, -7.2]),
        ];
        let labels = window_labels(&starts);
        let texts: Vec<&str> = labels.iter().map(|(t, _)| t.as_str()).collect();
        assert_eq!(texts, ["1", "2", "3, 4"]);
        assert_eq!(labels[2].1, [6.0, -7.0], "at the first window's place");
    }

    #[test]
    fn the_title_names_the_seed_and_the_legend_every_colour_drawn() {
        assert!(title(roam_mission::site::BUILTIN_DAY, 7, 20.0, 4)[0].contains("seed 7"));
        assert!(title("depot", 7, 20.0, 4)[1].contains("the site depot"));
        let colours: Vec<Rgb<u8>> = legend().iter().map(|e| e.colour).collect();
        for drawn in [
            INFORMATION,
            OCCUPIED,
            PATH,
            BASELINE,
            DRIVEN,
            ANCHOR,
            MARKER,
        ] {
            assert!(colours.contains(&drawn), "{drawn:?} in the legend");
        }
        // The built-in font draws ASCII only.
        for line in title("caf\u{e9}", 0, 20.0, 4) {
            assert!(line.is_ascii(), "{line}");
        }
    }
}
