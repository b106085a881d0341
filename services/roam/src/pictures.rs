//! The frames (title, legend, scale bar: `roam_world::legend`) of the binary's other
//! pictures, `roam plan --png` and `roam sim render`, so that they too explain
//! themselves. In the library so the tests find each part where the layout puts it.

use roam_world::legend::{Entry, Frame};
use roam_world::render::{INFORMATION, MARKER, OCCUPIED, PATH, UNKNOWN};

/// `roam plan --png`: the map, the zones of interest and one plan.
pub fn plan_frame(title: Vec<String>, pixels_per_metre: f64) -> Frame {
    Frame {
        title,
        legend: vec![
            Entry::fill(INFORMATION, "zone of interest (darker: more)"),
            Entry::fill(OCCUPIED, "wall"),
            Entry::fill(UNKNOWN, "unknown"),
            Entry::line(PATH, "the plan"),
            Entry::fill(MARKER, "start and goal"),
        ],
        text_scale: 2,
        pixels_per_metre: Some(pixels_per_metre),
    }
}

/// `roam sim render`: a scenario as the sim holds it at its first step.
pub fn scenario_frame(
    name: &str,
    size_m: (f64, f64),
    resolution: f64,
    pixels_per_metre: f64,
) -> Frame {
    Frame {
        title: vec![
            format!("roam sim render: {name}"),
            format!(
                "{:.0} x {:.0} m, {resolution} m cells, at the first step",
                size_m.0, size_m.1
            ),
        ],
        legend: vec![
            Entry::fill(INFORMATION, "zone of interest (darker: more)"),
            Entry::fill(OCCUPIED, "wall"),
            Entry::fill(UNKNOWN, "unknown"),
            Entry::fill(roam_sim::render::ANCHOR, "anchor"),
            Entry::line(roam_sim::render::RANGE_CIRCLE, "anchor's sensing range"),
            Entry::fill(roam_sim::render::ROBOT, "robot"),
            Entry::fill(roam_sim::render::MOVING, "block or walker"),
        ],
        text_scale: 2,
        pixels_per_metre: Some(pixels_per_metre),
    }
}
