//! A picture that explains itself: a map or chart framed with a title above it, a legend
//! beside it (each colour and what it means) and, for maps, a scale bar in metres
//! below it, drawn with the built-in [`font`](crate::font).
//!
//! The layout is a pure function of the picture's size and the [`Frame`]
//! ([`layout`]), so a test can find every swatch and the title in the written PNG.

use image::{Rgb, RgbImage};

use crate::font::{draw_text, text_height, text_width};

/// Paper.
pub const BACKGROUND: Rgb<u8> = Rgb([255, 255, 255]);
/// Text, the scale bar and label borders.
pub const INK: Rgb<u8> = Rgb([0, 0, 0]);
/// The outline of a filled swatch, so that a white or pale colour shows on the paper.
pub const OUTLINE: Rgb<u8> = Rgb([128, 128, 128]);
/// Space around the picture and between its parts, pixels.
pub const MARGIN: u32 = 10;
/// The title's font scale (14 px high letters).
pub const TITLE_SCALE: u32 = 2;

/// How a legend entry shows its colour.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Swatch {
    /// A filled box with a thin [`OUTLINE`]: areas, markers.
    Fill,
    /// A thick line: paths and curves.
    Line,
    /// A label as drawn on the picture (e.g. a window's number): [`draw_label`].
    Label(String),
}

/// One colour and what it means.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Entry {
    pub colour: Rgb<u8>,
    pub swatch: Swatch,
    pub text: String,
}

impl Entry {
    pub fn fill(colour: Rgb<u8>, text: &str) -> Entry {
        Entry {
            colour,
            swatch: Swatch::Fill,
            text: text.to_owned(),
        }
    }

    pub fn line(colour: Rgb<u8>, text: &str) -> Entry {
        Entry {
            colour,
            swatch: Swatch::Line,
            text: text.to_owned(),
        }
    }
}

/// What goes around a picture.
#[derive(Debug, Clone, PartialEq)]
pub struct Frame {
    /// What the picture shows and from which run (seed, sizes); ASCII. One line per
    /// element.
    pub title: Vec<String>,
    pub legend: Vec<Entry>,
    /// The font scale of the legend and the scale bar's label (1: 7 px letters).
    pub text_scale: u32,
    /// Picture pixels per metre, for the scale bar; `None` for charts.
    pub pixels_per_metre: Option<f64>,
}

/// Where a [`Frame`]'s parts go.
#[derive(Debug, Clone, PartialEq)]
pub struct Layout {
    /// The framed image's size.
    pub size: (u32, u32),
    /// Top-left corner of each title line.
    pub title: Vec<(u32, u32)>,
    /// Top-left corner of the framed picture.
    pub picture: (u32, u32),
    /// Top-left corner and size of each legend entry's swatch, in the legend's order.
    pub swatches: Vec<(u32, u32, u32, u32)>,
    /// The scale bar: its left end, its row, its length in pixels and in metres.
    pub scale_bar: Option<ScaleBar>,
}

/// A scale bar's place and length.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ScaleBar {
    pub x: u32,
    pub y: u32,
    pub pixels: u32,
    pub metres: f64,
}

/// The longest "nice" length (1, 2 or 5 times a power of ten metres) whose bar is at
/// most `max_pixels` long at `pixels_per_metre`; `None` if not even 1 mm fits.
pub fn nice_length(pixels_per_metre: f64, max_pixels: f64) -> Option<f64> {
    if !(pixels_per_metre.is_finite() && pixels_per_metre > 0.0 && max_pixels > 0.0) {
        return None;
    }
    let longest = max_pixels / pixels_per_metre;
    let mut best = None;
    for exponent in -3..=6 {
        for step in [1.0, 2.0, 5.0] {
            let metres = step * 10f64.powi(exponent);
            if metres <= longest {
                best = Some(metres);
            }
        }
    }
    best
}

/// The scale bar's label: `5 m`, `0.5 m`, `200 m`.
pub fn metres_label(metres: f64) -> String {
    format!("{metres} m")
}

fn row_height(scale: u32) -> u32 {
    text_height(scale) + 4 * scale.max(1)
}

fn swatch_width(entry: &Entry, scale: u32) -> u32 {
    match &entry.swatch {
        Swatch::Label(text) => text_width(text, scale) + 4 * scale,
        _ => 7 * scale.max(1) * 2,
    }
}

/// Where everything goes when `frame` is put around a picture of `picture` size:
/// the title lines at the top left, the picture under them, the legend to its right
/// (one entry a row, swatch then text), the scale bar under the picture.
pub fn layout(picture: (u32, u32), frame: &Frame) -> Layout {
    let scale = frame.text_scale.max(1);
    let title_line = text_height(TITLE_SCALE) + 6;
    let title: Vec<(u32, u32)> = (0..frame.title.len() as u32)
        .map(|k| (MARGIN, MARGIN + k * title_line))
        .collect();
    let top = MARGIN + frame.title.len() as u32 * title_line + MARGIN / 2;
    let picture_at = (MARGIN, top);
    let legend_x = MARGIN + picture.0 + 2 * MARGIN;
    let row = row_height(scale);
    let swatch_column = frame
        .legend
        .iter()
        .map(|e| swatch_width(e, scale))
        .max()
        .unwrap_or(0);
    let swatches: Vec<(u32, u32, u32, u32)> = frame
        .legend
        .iter()
        .enumerate()
        .map(|(k, e)| {
            let (w, h) = match e.swatch {
                Swatch::Line => (swatch_width(e, scale), (2 * scale).max(3)),
                _ => (swatch_width(e, scale), text_height(scale) + 2 * scale),
            };
            let y = top + k as u32 * row + (row - h) / 2;
            (legend_x, y, w, h)
        })
        .collect();
    let legend_w = frame
        .legend
        .iter()
        .map(|e| swatch_column + 3 * scale + text_width(&e.text, scale))
        .max()
        .map_or(0, |w| w + 2 * MARGIN);
    let legend_h = frame.legend.len() as u32 * row;
    let scale_bar = frame.pixels_per_metre.and_then(|ppm| {
        let metres = nice_length(ppm, f64::from(picture.0) / 4.0)?;
        Some(ScaleBar {
            x: MARGIN,
            y: top + picture.1 + MARGIN + text_height(scale) / 2,
            pixels: (metres * ppm).round() as u32,
            metres,
        })
    });
    let below = match scale_bar {
        Some(_) => MARGIN + text_height(scale) + MARGIN,
        None => MARGIN,
    };
    let title_w = frame
        .title
        .iter()
        .map(|t| MARGIN + text_width(t, TITLE_SCALE) + MARGIN)
        .max()
        .unwrap_or(0);
    let width = (legend_x + legend_w)
        .max(title_w)
        .max(MARGIN + picture.0 + MARGIN);
    let height = (top + picture.1 + below).max(top + legend_h + MARGIN);
    Layout {
        size: (width, height),
        title,
        picture: picture_at,
        swatches,
        scale_bar,
    }
}

/// `picture` with `frame` around it, as [`layout`] places it.
pub fn framed(picture: &RgbImage, frame: &Frame) -> RgbImage {
    let at = layout(picture.dimensions(), frame);
    let mut out = RgbImage::from_pixel(at.size.0, at.size.1, BACKGROUND);
    for (x, y, p) in picture.enumerate_pixels() {
        out.put_pixel(at.picture.0 + x, at.picture.1 + y, *p);
    }
    for (line, (x, y)) in frame.title.iter().zip(&at.title) {
        draw_text(
            &mut out,
            i64::from(*x),
            i64::from(*y),
            line,
            TITLE_SCALE,
            INK,
        );
    }
    let scale = frame.text_scale.max(1);
    let text_x = at.swatches.iter().map(|s| s.0 + s.2).max().unwrap_or(0) + 3 * scale;
    for (entry, &(x, y, w, h)) in frame.legend.iter().zip(&at.swatches) {
        match &entry.swatch {
            Swatch::Label(text) => draw_label(&mut out, x, y, text, scale, entry.colour),
            Swatch::Fill => {
                fill(&mut out, x, y, w, h, OUTLINE);
                fill(&mut out, x + 1, y + 1, w - 2, h - 2, entry.colour);
            }
            Swatch::Line => fill(&mut out, x, y, w, h, entry.colour),
        }
        let text_y = y + h / 2 - text_height(scale) / 2;
        draw_text(
            &mut out,
            i64::from(text_x),
            i64::from(text_y),
            &entry.text,
            scale,
            INK,
        );
    }
    if let Some(bar) = at.scale_bar {
        let thick = (scale * 2).max(3);
        fill(&mut out, bar.x, bar.y, bar.pixels, thick, INK);
        for end in [bar.x, bar.x + bar.pixels.saturating_sub(2)] {
            fill(
                &mut out,
                end,
                bar.y.saturating_sub(3 * scale),
                2,
                thick + 6 * scale,
                INK,
            );
        }
        draw_text(
            &mut out,
            i64::from(bar.x + bar.pixels + 4 * scale),
            i64::from(bar.y + thick / 2) - i64::from(text_height(scale) / 2),
            &metres_label(bar.metres),
            scale,
            INK,
        );
    }
    out
}

/// A filled rectangle, clipped to the image.
pub fn fill(image: &mut RgbImage, x: u32, y: u32, w: u32, h: u32, colour: Rgb<u8>) {
    for py in y..(y + h).min(image.height()) {
        for px in x..(x + w).min(image.width()) {
            image.put_pixel(px, py, colour);
        }
    }
}

/// Text in `colour` on a white box with a border in `colour`, its top-left corner at
/// (`x`, `y`): readable over a map whatever is under it (window numbers on a path).
pub fn draw_label(image: &mut RgbImage, x: u32, y: u32, text: &str, scale: u32, colour: Rgb<u8>) {
    let scale = scale.max(1);
    let (w, h) = (
        text_width(text, scale) + 4 * scale,
        text_height(scale) + 2 * scale,
    );
    fill(image, x, y, w, h, colour);
    fill(
        image,
        x + 1,
        y + 1,
        w.saturating_sub(2),
        h.saturating_sub(2),
        BACKGROUND,
    );
    draw_text(
        image,
        i64::from(x + 2 * scale),
        i64::from(y + scale),
        text,
        scale,
        colour,
    );
}

/// The size of a [`draw_label`] box.
pub fn label_size(text: &str, scale: u32) -> (u32, u32) {
    let scale = scale.max(1);
    (
        text_width(text, scale) + 4 * scale,
        text_height(scale) + 2 * scale,
    )
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::font::ink;

    fn frame() -> Frame {
        Frame {
            title: vec!["A title".into(), "seed 3".into()],
            legend: vec![
                Entry::fill(Rgb([0, 170, 60]), "tasks"),
                Entry::line(Rgb([220, 20, 20]), "driven path"),
                Entry {
                    colour: Rgb([0, 0, 0]),
                    swatch: Swatch::Label("1".into()),
                    text: "window 1 begins".into(),
                },
            ],
            text_scale: 2,
            pixels_per_metre: Some(40.0),
        }
    }

    #[test]
    fn the_frame_holds_the_picture_title_legend_and_scale_where_the_layout_says() {
        let grey = Rgb([120, 120, 120]);
        let picture = RgbImage::from_pixel(200, 100, grey);
        let frame = frame();
        let at = layout(picture.dimensions(), &frame);
        let out = framed(&picture, &frame);
        assert_eq!(out.dimensions(), at.size);
        // The picture, whole, where the layout puts it.
        assert_eq!(*out.get_pixel(at.picture.0, at.picture.1), grey);
        assert_eq!(*out.get_pixel(at.picture.0 + 199, at.picture.1 + 99), grey);
        // Each fill swatch is its colour inside its outline, a line swatch all over;
        // the label swatch is its border colour at its corner.
        for (entry, &(x, y, w, h)) in frame.legend.iter().zip(&at.swatches) {
            assert!(x >= at.picture.0 + 200, "right of the picture");
            match entry.swatch {
                Swatch::Label(_) => assert_eq!(*out.get_pixel(x, y), entry.colour),
                Swatch::Fill => {
                    assert_eq!(*out.get_pixel(x, y), OUTLINE);
                    for (px, py) in [
                        (x + 1, y + 1),
                        (x + w - 2, y + h - 2),
                        (x + w / 2, y + h / 2),
                    ] {
                        assert_eq!(*out.get_pixel(px, py), entry.colour, "{}", entry.text);
                    }
                }
                Swatch::Line => {
                    for (px, py) in [(x, y), (x + w - 1, y + h - 1)] {
                        assert_eq!(*out.get_pixel(px, py), entry.colour, "{}", entry.text);
                    }
                }
            }
        }
        // The title's letters: every ink pixel of the first line's "A" is ink.
        let (tx, ty) = at.title[0];
        for gx in 0..5 {
            for gy in 0..7 {
                let p = *out.get_pixel(tx + gx * TITLE_SCALE, ty + gy * TITLE_SCALE);
                assert_eq!(p == INK, ink('A', gx, gy), "A at ({gx}, {gy})");
            }
        }
        // 40 px per metre, a bar at most a quarter of 200 px: 1 m, 40 px.
        let bar = at.scale_bar.expect("a scale bar");
        assert_eq!((bar.metres, bar.pixels), (1.0, 40));
        assert!(bar.y > at.picture.1 + 100, "under the picture");
        assert_eq!(*out.get_pixel(bar.x + 20, bar.y + 1), INK);
    }

    #[test]
    fn scale_bars_have_nice_lengths() {
        assert_eq!(nice_length(40.0, 50.0), Some(1.0));
        assert_eq!(nice_length(40.0, 90.0), Some(2.0));
        assert_eq!(nice_length(8.0 / 0.2, 200.0), Some(5.0));
        assert_eq!(nice_length(12.0, 180.0), Some(10.0));
        assert_eq!(nice_length(0.0, 100.0), None);
        assert_eq!(metres_label(0.5), "0.5 m");
        assert_eq!(metres_label(20.0), "20 m");
    }
}
