//! The check of all the sim world's sections of a scenario file against its map: every
//! item on the map, robots and walkers on free cells, names unique.

use roam_proto::map::GridMeta;

use super::changes;
use super::field_issue::FieldIssue;
use super::file::ScenarioFile;
use super::sim_sections::is_blocked;
use crate::grid::{occupancy, Grid};

/// The cell a sim item stands in, or why it cannot stand there.
fn cell_on_map(
    meta: &GridMeta,
    field: String,
    what: &str,
    [x, y]: [f64; 2],
) -> Result<(usize, usize), FieldIssue> {
    if !(x.is_finite() && y.is_finite()) {
        return Err(FieldIssue::new(
            field,
            format!("{what}: coordinates must be numbers, got ({x}, {y})"),
        ));
    }
    crate::grid::world_to_cell(meta, x, y).ok_or_else(|| {
        let (x0, y0) = (meta.origin.x, meta.origin.y);
        let x1 = x0 + f64::from(meta.width) * meta.resolution;
        let y1 = y0 + f64::from(meta.height) * meta.resolution;
        FieldIssue::new(
            field,
            format!(
                "{what} at ({x}, {y}) is outside the map, which spans x {x0}..{x1} and \
                 y {y0}..{y1} m"
            ),
        )
    })
}

/// Checks that a sim item starts on a free cell of the static map.
fn on_free_cell(
    occupancy: &Grid<i8>,
    field: String,
    what: &str,
    at: [f64; 2],
) -> Result<(), FieldIssue> {
    let (cx, cy) = cell_on_map(&occupancy.meta, field.clone(), what, at)?;
    match occupancy.get(cx, cy) {
        Some(v) if !is_blocked(v) => Ok(()),
        v => Err(FieldIssue::new(
            field,
            format!(
                "{what} at ({}, {}) is on an occupied or unknown cell (value {}); it must \
                 start on a free cell",
                at[0],
                at[1],
                v.unwrap_or(occupancy::UNKNOWN)
            ),
        )),
    }
}

/// Checks the sim world's sections against the map.
pub(crate) fn validate_sim(file: &ScenarioFile, occupancy: &Grid<i8>) -> Result<(), FieldIssue> {
    let meta = &occupancy.meta;
    let on_map = |f: String, what: &str, at: [f64; 2]| cell_on_map(meta, f, what, at);
    let on_free_cell = |f: String, what: &str, at: [f64; 2]| on_free_cell(occupancy, f, what, at);
    let unique = |list: &str, names: Vec<&str>| -> Result<(), FieldIssue> {
        for (i, name) in names.iter().enumerate() {
            if name.is_empty() {
                return Err(FieldIssue::new(
                    format!("{list}[{i}].name"),
                    "a name must not be empty",
                ));
            }
            if names[..i].contains(name) {
                return Err(FieldIssue::new(
                    format!("{list}[{i}].name"),
                    format!("the name '{name}' is used twice in {list}"),
                ));
            }
        }
        Ok(())
    };

    unique(
        "anchors",
        file.anchors.iter().map(|a| a.name.as_str()).collect(),
    )?;
    for (i, anchor) in file.anchors.iter().enumerate() {
        on_map(
            format!("anchors[{i}].at"),
            &format!("anchor '{}'", anchor.name),
            anchor.at,
        )?;
    }
    file.sensing.check(meta.resolution)?;
    file.motion.check()?;
    file.time.check()?;
    unique(
        "robots",
        file.robots.iter().map(|r| r.name.as_str()).collect(),
    )?;
    for (i, robot) in file.robots.iter().enumerate() {
        on_free_cell(
            format!("robots[{i}].at"),
            &format!("robot '{}'", robot.name),
            robot.at,
        )?;
        robot.check_heading(&format!("robots[{i}]"))?;
    }
    unique(
        "blocks",
        file.blocks.iter().map(|b| b.name.as_str()).collect(),
    )?;
    for (i, block) in file.blocks.iter().enumerate() {
        let f = |sub: &str| format!("blocks[{i}].{sub}");
        match (block.size_cells, block.size_m) {
            (Some([w, h]), None) if w >= 1 && h >= 1 => {}
            (Some(size), None) => {
                return Err(FieldIssue::new(
                    f("size_cells"),
                    format!(
                        "block '{}': both sizes must be at least 1 cell, got {size:?}",
                        block.name
                    ),
                ));
            }
            (None, Some([w, h])) if w.is_finite() && h.is_finite() && w > 0.0 && h > 0.0 => {}
            (None, Some(size)) => {
                return Err(FieldIssue::new(
                    f("size_m"),
                    format!(
                        "block '{}': both sizes must be positive metres, got {size:?}",
                        block.name
                    ),
                ));
            }
            _ => {
                return Err(FieldIssue::new(
                    format!("blocks[{i}]"),
                    format!(
                        "block '{}' needs exactly one of size_cells or size_m",
                        block.name
                    ),
                ));
            }
        }
        if block.path.is_empty() {
            return Err(FieldIssue::new(
                f("path"),
                format!("block '{}' needs at least one position", block.name),
            ));
        }
        for (j, &at) in block.path.iter().enumerate() {
            on_map(
                f(&format!("path[{j}]")),
                &format!("block '{}' position {j}", block.name),
                at,
            )?;
        }
        if block.period_steps == 0 {
            return Err(FieldIssue::new(
                f("period_steps"),
                format!("block '{}': must be at least 1 step", block.name),
            ));
        }
    }
    unique(
        "walkers",
        file.walkers.iter().map(|w| w.name.as_str()).collect(),
    )?;
    for (i, walker) in file.walkers.iter().enumerate() {
        let f = |sub: &str| format!("walkers[{i}].{sub}");
        on_free_cell(f("at"), &format!("walker '{}'", walker.name), walker.at)?;
        if !(walker.size_m.is_finite() && walker.size_m > 0.0) {
            return Err(FieldIssue::new(
                f("size_m"),
                format!(
                    "walker '{}': must be a positive number of metres, got {}",
                    walker.name, walker.size_m
                ),
            ));
        }
        if !(walker.step_m.is_finite() && walker.step_m > 0.0) {
            return Err(FieldIssue::new(
                f("step_m"),
                format!(
                    "walker '{}': must be a positive number of metres, got {}",
                    walker.name, walker.step_m
                ),
            ));
        }
        if walker.every_steps == 0 {
            return Err(FieldIssue::new(
                f("every_steps"),
                format!("walker '{}': must be at least 1 step", walker.name),
            ));
        }
    }
    let (x0, y0) = (meta.origin.x, meta.origin.y);
    let extent = [
        x0,
        y0,
        x0 + f64::from(meta.width) * meta.resolution,
        y0 + f64::from(meta.height) * meta.resolution,
    ];
    changes::check(&file.changes, extent)?;
    unique(
        "waypoints",
        file.waypoints.iter().map(|w| w.name.as_str()).collect(),
    )?;
    for (i, waypoint) in file.waypoints.iter().enumerate() {
        on_map(
            format!("waypoints[{i}].at"),
            &format!("waypoint '{}'", waypoint.name),
            waypoint.at,
        )?;
    }
    Ok(())
}
