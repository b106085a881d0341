//! The fleet's week as pictures, in SVG (title, legend and scale bar as `<text>` and
//! shapes: no font to ship):
//!
//! - `warehouse-<variant>.svg`: the warehouse (racks and walls), its change zones
//!   shaded by how often objects land there, the anchors, each robot's true path
//!   through the first shift, and every change of the week at its place: green when
//!   the fleet saw it within ten minutes, orange later, red never;
//! - `detection.svg`: for each variant, the share of the week's changes the fleet had
//!   seen within t minutes of the change (higher and further left is better).

use std::fmt::Write;
use std::path::{Path, PathBuf};

use roam_world::scenario::is_blocked;

use super::measure::WeekRecord;
use super::world::FleetWorld;

/// Pixels per metre of the warehouse picture.
const PX_PER_M: f64 = 12.0;
/// Room right of the map for the legend, pixels.
const LEGEND_W: f64 = 260.0;
/// Seen within this many seconds: green.
const SOON_S: f64 = 600.0;
/// The robots' colours, in turn.
pub const ROBOT_COLOURS: [&str; 10] = [
    "#1f77b4", "#ff7f0e", "#2ca02c", "#d62728", "#9467bd", "#8c564b", "#e377c2", "#7f7f7f",
    "#bcbd22", "#17becf",
];
/// The variants' colours in the detection plot, in turn.
const VARIANT_COLOURS: [&str; 7] = [
    "#7f7f7f", "#d62728", "#1f77b4", "#2ca02c", "#9467bd", "#ff7f0e", "#17becf",
];
/// The detection plot's horizon, minutes.
const HORIZON_MIN: f64 = 60.0;

/// A legend entry's mark.
enum Mark {
    /// A filled square of this opacity.
    Square(f64),
    Dot,
    Line,
}

fn escape(text: &str) -> String {
    text.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
}

/// The warehouse with `week`'s first-shift paths and its changes; `seed` is the batch's,
/// for the title.
pub fn warehouse_svg(world: &FleetWorld, week: &WeekRecord, seed: u64) -> String {
    let scenario = &world.setup.scenario;
    let meta = scenario.occupancy.meta;
    let (w_m, h_m) = (
        f64::from(meta.width) * meta.resolution,
        f64::from(meta.height) * meta.resolution,
    );
    let (ox, oy) = (meta.origin.x, meta.origin.y);
    // World metres to picture pixels, north up.
    let px = |p: [f64; 2]| ((p[0] - ox) * PX_PER_M, (oy + h_m - p[1]) * PX_PER_M);
    let (width, height) = (w_m * PX_PER_M + LEGEND_W, h_m * PX_PER_M);
    let mut svg = String::new();
    let _ = writeln!(
        svg,
        r#"<svg xmlns="http://www.w3.org/2000/svg" width="{width:.0}" height="{height:.0}" font-family="sans-serif" font-size="13">"#
    );
    let _ = writeln!(
        svg,
        r##"<rect x="0" y="0" width="{width:.0}" height="{height:.0}" fill="#ffffff"/>"##
    );
    // Change zones, by rate: the hottest darkest.
    let hottest = scenario
        .file
        .changes
        .iter()
        .map(|z| z.appear_per_hour)
        .fold(0.0_f64, f64::max)
        .max(f64::MIN_POSITIVE);
    let _ = writeln!(svg, r#"<g id="zones">"#);
    for z in &scenario.file.changes {
        let (x0, y1) = px([z.rect[0], z.rect[1]]);
        let (x1, y0) = px([z.rect[2], z.rect[3]]);
        let opacity = 0.08 + 0.4 * (z.appear_per_hour / hottest);
        let _ = writeln!(
            svg,
            r##"<rect x="{x0:.1}" y="{y0:.1}" width="{:.1}" height="{:.1}" fill="#e8a000" fill-opacity="{opacity:.2}"><title>{} ({:.1} per hour)</title></rect>"##,
            x1 - x0,
            y1 - y0,
            escape(&z.name),
            z.appear_per_hour
        );
    }
    let _ = writeln!(svg, "</g>");
    // Walls and racks: runs of blocked cells on the planner's grid.
    let grid = &world.static_coarse;
    let cm = grid.meta;
    let cell_px = cm.resolution * PX_PER_M;
    let _ = writeln!(svg, r##"<g id="racks" fill="#3a3a3a">"##);
    for y in 0..cm.height as usize {
        let mut x = 0;
        while x < cm.width as usize {
            if !is_blocked(grid.cells[y * cm.width as usize + x]) {
                x += 1;
                continue;
            }
            let start = x;
            while x < cm.width as usize && is_blocked(grid.cells[y * cm.width as usize + x]) {
                x += 1;
            }
            let wx = cm.origin.x + start as f64 * cm.resolution;
            let wy = cm.origin.y + (y + 1) as f64 * cm.resolution;
            let (sx, sy) = px([wx, wy]);
            let _ = writeln!(
                svg,
                r#"<rect x="{sx:.1}" y="{sy:.1}" width="{:.1}" height="{cell_px:.1}"/>"#,
                (x - start) as f64 * cell_px
            );
        }
    }
    let _ = writeln!(svg, "</g>");
    // Paths.
    let _ = writeln!(svg, r#"<g id="paths" fill="none" stroke-width="1.5">"#);
    for (i, path) in week.paths.iter().enumerate().filter(|(_, p)| p.len() > 1) {
        let points: Vec<String> = path
            .iter()
            .map(|&p| {
                let (x, y) = px(p);
                format!("{x:.1},{y:.1}")
            })
            .collect();
        let _ = writeln!(
            svg,
            r#"<polyline class="path" stroke="{}" stroke-opacity="0.8" points="{}"/>"#,
            ROBOT_COLOURS[i % ROBOT_COLOURS.len()],
            points.join(" ")
        );
    }
    let _ = writeln!(svg, "</g>");
    // Changes.
    let _ = writeln!(
        svg,
        r##"<g id="changes" stroke="#000000" stroke-width="0.5">"##
    );
    for e in &week.events {
        let [x0, y0, x1, y1] = e.bounds();
        let centre = [
            ox + (x0 + x1 + 1) as f64 * 0.5 * meta.resolution,
            oy + (y0 + y1 + 1) as f64 * 0.5 * meta.resolution,
        ];
        let (x, y) = px(centre);
        let colour = match e.latency_s() {
            Some(l) if l <= SOON_S => "#2ca02c",
            Some(_) => "#ff7f0e",
            None => "#d62728",
        };
        let _ = writeln!(
            svg,
            r#"<circle class="change" cx="{x:.1}" cy="{y:.1}" r="3" fill="{colour}"/>"#
        );
    }
    let _ = writeln!(svg, "</g>");
    // Anchors.
    let _ = writeln!(svg, r##"<g id="anchors" fill="#000000">"##);
    for a in &scenario.file.anchors {
        let (x, y) = px(a.at);
        let _ = writeln!(
            svg,
            r#"<rect x="{:.1}" y="{:.1}" width="6" height="6"/>"#,
            x - 3.0,
            y - 3.0
        );
    }
    let _ = writeln!(svg, "</g>");
    // Legend.
    let lx = w_m * PX_PER_M + 16.0;
    let _ = writeln!(
        svg,
        r#"<text id="title" x="{lx:.1}" y="20" font-weight="bold">{}</text>"#,
        escape(&format!(
            "roam fleet: {}, first shift, seed {seed}",
            week.variant.name()
        ))
    );
    let mut entries: Vec<(Mark, String, String)> = vec![
        (
            Mark::Square(1.0),
            "#3a3a3a".into(),
            "racks and walls".into(),
        ),
        (
            Mark::Square(0.45),
            "#e8a000".into(),
            "change zone (darker: objects land more often)".into(),
        ),
        (Mark::Square(1.0), "#000000".into(), "UWB anchor".into()),
        (
            Mark::Dot,
            "#2ca02c".into(),
            "change seen within 10 min".into(),
        ),
        (Mark::Dot, "#ff7f0e".into(), "change seen later".into()),
        (Mark::Dot, "#d62728".into(), "change never seen".into()),
    ];
    for i in 0..week.paths.len() {
        entries.push((
            Mark::Line,
            ROBOT_COLOURS[i % ROBOT_COLOURS.len()].into(),
            format!("robot {}'s path, first shift", i + 1),
        ));
    }
    for (k, (mark, colour, text)) in entries.iter().enumerate() {
        let ly = 44.0 + 20.0 * k as f64;
        let _ = match mark {
            Mark::Square(opacity) => writeln!(
                svg,
                r#"<rect x="{lx:.1}" y="{:.1}" width="14" height="10" fill="{colour}" fill-opacity="{opacity}"/>"#,
                ly - 5.0
            ),
            Mark::Dot => writeln!(
                svg,
                r#"<circle cx="{:.1}" cy="{ly:.1}" r="4" fill="{colour}" stroke="black" stroke-width="0.5"/>"#,
                lx + 7.0
            ),
            Mark::Line => writeln!(
                svg,
                r#"<line x1="{lx:.1}" y1="{ly:.1}" x2="{:.1}" y2="{ly:.1}" stroke="{colour}" stroke-width="3"/>"#,
                lx + 14.0
            ),
        };
        let _ = writeln!(
            svg,
            r#"<text class="legend" x="{:.1}" y="{:.1}">{}</text>"#,
            lx + 22.0,
            ly + 4.0,
            escape(text)
        );
    }
    // Scale bar: 10 m, under the legend.
    let (sy, bar) = (44.0 + 20.0 * entries.len() as f64 + 10.0, 10.0 * PX_PER_M);
    let _ = writeln!(
        svg,
        r##"<g id="scale"><rect x="{lx:.1}" y="{sy:.1}" width="{bar:.1}" height="4" fill="#000000"/><text x="{:.1}" y="{:.1}">10 m</text></g>"##,
        lx + bar + 8.0,
        sy + 6.0
    );
    svg.push_str("</svg>\n");
    svg
}

/// The share of each variant's changes seen within t minutes, t from 0 to an hour;
/// `seed` is the batch's, for the title.
pub fn detection_svg(weeks: &[WeekRecord], seed: u64) -> String {
    let (left, top, plot_w, plot_h) = (60.0, 50.0, 520.0, 320.0);
    let (width, height) = (left + plot_w + 230.0, top + plot_h + 60.0);
    let x_of = |minutes: f64| left + plot_w * (minutes / HORIZON_MIN).clamp(0.0, 1.0);
    let y_of = |share: f64| top + plot_h * (1.0 - share.clamp(0.0, 1.0));
    let mut svg = String::new();
    let _ = writeln!(
        svg,
        r##"<svg xmlns="http://www.w3.org/2000/svg" width="{width:.0}" height="{height:.0}" font-family="sans-serif" font-size="13"><rect x="0" y="0" width="{width:.0}" height="{height:.0}" fill="#ffffff"/>"##
    );
    // Axes and ticks.
    let _ = writeln!(
        svg,
        r##"<g id="axes" stroke="#000000"><line x1="{left}" y1="{:.1}" x2="{:.1}" y2="{:.1}"/><line x1="{left}" y1="{top}" x2="{left}" y2="{:.1}"/></g>"##,
        top + plot_h,
        left + plot_w,
        top + plot_h,
        top + plot_h
    );
    for m in (0..=60).step_by(10) {
        let x = x_of(f64::from(m));
        let _ = writeln!(
            svg,
            r#"<text x="{x:.1}" y="{:.1}" text-anchor="middle">{m}</text>"#,
            top + plot_h + 18.0
        );
    }
    for s in 0..=4 {
        let share = f64::from(s) / 4.0;
        let _ = writeln!(
            svg,
            r#"<text x="{:.1}" y="{:.1}" text-anchor="end">{share:.2}</text>"#,
            left - 6.0,
            y_of(share) + 4.0
        );
    }
    let _ = writeln!(
        svg,
        r#"<text x="{:.1}" y="{:.1}" text-anchor="middle">minutes from a change to the fleet's first sight of it</text>"#,
        left + plot_w / 2.0,
        top + plot_h + 40.0
    );
    let _ = writeln!(
        svg,
        r#"<text id="title" x="{left}" y="20" font-weight="bold">{}</text>"#,
        escape(&format!(
            "roam fleet: how soon the changes were seen, {} variants, seed {seed}",
            weeks.len()
        ))
    );
    let _ = writeln!(
        svg,
        r#"<text x="{left}" y="40">share of the week's changes seen</text>"#
    );
    for (i, week) in weeks.iter().enumerate() {
        let colour = VARIANT_COLOURS[i % VARIANT_COLOURS.len()];
        let total = week.events.len().max(1) as f64;
        let mut latencies: Vec<f64> = week.events.iter().filter_map(|e| e.latency_s()).collect();
        latencies.sort_by(f64::total_cmp);
        // A step curve: the share seen by each latency.
        let mut points = vec![format!("{:.1},{:.1}", x_of(0.0), y_of(0.0))];
        for (k, l) in latencies.iter().enumerate() {
            let minutes = l / 60.0;
            if minutes > HORIZON_MIN {
                break;
            }
            points.push(format!(
                "{:.1},{:.1}",
                x_of(minutes),
                y_of(k as f64 / total)
            ));
            points.push(format!(
                "{:.1},{:.1}",
                x_of(minutes),
                y_of((k + 1) as f64 / total)
            ));
        }
        let seen_by_end = latencies
            .iter()
            .filter(|l| **l / 60.0 <= HORIZON_MIN)
            .count();
        points.push(format!(
            "{:.1},{:.1}",
            x_of(HORIZON_MIN),
            y_of(seen_by_end as f64 / total)
        ));
        let _ = writeln!(
            svg,
            r#"<polyline class="variant" fill="none" stroke="{colour}" stroke-width="2" points="{}"/>"#,
            points.join(" ")
        );
        let ly = top + 10.0 + 20.0 * i as f64;
        let lx = left + plot_w + 20.0;
        let _ = writeln!(
            svg,
            r#"<line x1="{lx:.1}" y1="{ly:.1}" x2="{:.1}" y2="{ly:.1}" stroke="{colour}" stroke-width="3"/><text class="legend" x="{:.1}" y="{:.1}">{}</text>"#,
            lx + 16.0,
            lx + 22.0,
            ly + 4.0,
            escape(week.variant.name())
        );
    }
    svg.push_str("</svg>\n");
    svg
}

/// Writes `detection.svg` and one warehouse picture per week into `dir`.
pub fn write(
    dir: &Path,
    world: &FleetWorld,
    weeks: &[WeekRecord],
    seed: u64,
) -> std::io::Result<Vec<PathBuf>> {
    std::fs::create_dir_all(dir)?;
    let mut written = Vec::new();
    let detection = dir.join("detection.svg");
    std::fs::write(&detection, detection_svg(weeks, seed))?;
    written.push(detection);
    for week in weeks {
        let path = dir.join(format!("warehouse-{}.svg", week.variant.name()));
        std::fs::write(&path, warehouse_svg(world, week, seed))?;
        written.push(path);
    }
    Ok(written)
}
