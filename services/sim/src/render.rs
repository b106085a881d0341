//! `roam sim render`: a picture of a scenario as the sim holds it: the map with its
//! zones of interest, anchors with their sensing-range circles, blocks and walkers,
//! robots.

use image::{Rgb, RgbImage};
use roam_world::render::{render_map, OCCUPIED};

use crate::sim::Sim;

pub const ANCHOR: Rgb<u8> = Rgb([140, 0, 200]);
pub const RANGE_CIRCLE: Rgb<u8> = Rgb([190, 140, 230]);
pub const ROBOT: Rgb<u8> = Rgb([0, 160, 200]);
pub const MOVING: Rgb<u8> = Rgb([170, 30, 30]);

/// Pixels per cell that keep the picture near 800 pixels on its longer side.
pub fn auto_scale(sim: &Sim) -> u32 {
    let meta = sim.scenario().occupancy.meta;
    (800 / meta.width.max(meta.height).max(1)).clamp(1, 16)
}

/// Draws the sim's world at its current step, `scale` pixels per cell.
pub fn render(sim: &Sim, scale: u32) -> RgbImage {
    let scale = scale.max(1);
    let scenario = sim.scenario();
    let meta = scenario.occupancy.meta;
    let mut image = render_map(&scenario.occupancy, Some(&scenario.information), scale);
    let to_pixel = |x: f64, y: f64| -> (f64, f64) {
        let px = (x - meta.origin.x) / meta.resolution * f64::from(scale);
        let py = f64::from(meta.height * scale)
            - (y - meta.origin.y) / meta.resolution * f64::from(scale);
        (px, py)
    };
    // Blocks and walkers: cells the sim blocks that the static map leaves free.
    let dynamic = sim.occupancy();
    for (i, (&now, &fixed)) in dynamic
        .cells
        .iter()
        .zip(&scenario.occupancy.cells)
        .enumerate()
    {
        if now >= 65 && fixed < 65 {
            let (x, y) = (i as u32 % meta.width, i as u32 / meta.width);
            fill_rect(
                &mut image,
                x * scale,
                (meta.height - 1 - y) * scale,
                scale,
                scale,
                MOVING,
            );
        }
    }
    let pixels_per_metre = f64::from(scale) / meta.resolution;
    let range = sim.params().sensing.range_m * pixels_per_metre;
    for anchor in sim.anchors() {
        let (cx, cy) = to_pixel(anchor.at[0], anchor.at[1]);
        circle(&mut image, cx, cy, range, RANGE_CIRCLE);
        disc(
            &mut image,
            cx,
            cy,
            (1.5 * f64::from(scale)).max(4.0),
            ANCHOR,
        );
    }
    for robot in sim.robots() {
        let [x, y] = robot.position();
        let (cx, cy) = to_pixel(x, y);
        disc(&mut image, cx, cy, (1.2 * f64::from(scale)).max(4.0), ROBOT);
    }
    image
}

fn put(image: &mut RgbImage, x: i64, y: i64, colour: Rgb<u8>) {
    if x >= 0 && y >= 0 && (x as u32) < image.width() && (y as u32) < image.height() {
        image.put_pixel(x as u32, y as u32, colour);
    }
}

fn fill_rect(image: &mut RgbImage, x0: u32, y0: u32, w: u32, h: u32, colour: Rgb<u8>) {
    for y in y0..y0 + h {
        for x in x0..x0 + w {
            put(image, i64::from(x), i64::from(y), colour);
        }
    }
}

fn disc(image: &mut RgbImage, cx: f64, cy: f64, r: f64, colour: Rgb<u8>) {
    let (x0, x1) = ((cx - r).floor() as i64, (cx + r).ceil() as i64);
    let (y0, y1) = ((cy - r).floor() as i64, (cy + r).ceil() as i64);
    for y in y0..=y1 {
        for x in x0..=x1 {
            let (dx, dy) = (x as f64 + 0.5 - cx, y as f64 + 0.5 - cy);
            if dx * dx + dy * dy <= r * r {
                put(image, x, y, colour);
            }
        }
    }
}

/// A one-pixel circle outline that leaves walls visible.
fn circle(image: &mut RgbImage, cx: f64, cy: f64, r: f64, colour: Rgb<u8>) {
    let steps = (2.0 * std::f64::consts::PI * r).ceil().max(8.0) as usize;
    for k in 0..steps {
        let a = k as f64 / steps as f64 * std::f64::consts::TAU;
        let (x, y) = ((cx + r * a.cos()) as i64, (cy + r * a.sin()) as i64);
        if x >= 0
            && y >= 0
            && (x as u32) < image.width()
            && (y as u32) < image.height()
            && *image.get_pixel(x as u32, y as u32) != OCCUPIED
        {
            image.put_pixel(x as u32, y as u32, colour);
        }
    }
}
