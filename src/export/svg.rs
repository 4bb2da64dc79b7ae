//! SVG export of drawn lines: feature edges (House & Li), occluding and
//! suggestive contours (DeCarlo et al. 2003) and every other line family of
//! `shapecue lines`, one SVG group per cue or family (its own
//! id, class, colour and stroke width, so that users can restyle each cue).
//! Which parts of the lines are visible, joined into polylines, the renderer
//! finds against its depth buffer ([`crate::render::depth_visibility`], whose items
//! are re-exported here).

use std::fmt::Write as _;
use std::path::Path;

use crate::error::Result;
pub use crate::render::depth_visibility::{
    ClipLine, DEFAULT_BIAS, SvgPolyline, edge_out_lines, segment_lines, visible_joined,
};

/// One cue's group in the SVG file.
#[derive(Clone, Debug)]
pub struct SvgLayer {
    /// Group id and class (`contours`, `suggestive`, `ridges`, ..., `feature-edges`).
    pub id: &'static str,
    /// Stroke width in pixels.
    pub stroke_width: f32,
    /// Stroke colour, linear 0..1 components written as `#rrggbb`.
    pub color: [f32; 3],
    /// The joined visible lines.
    pub lines: Vec<SvgPolyline>,
    /// Dashed strokes (hidden parts drawn dashed).
    pub dashed: bool,
}

fn hex(c: [f32; 3]) -> String {
    let b = |x: f32| (x.clamp(0.0, 1.0) * 255.0).round() as u8;
    format!("#{:02x}{:02x}{:02x}", b(c[0]), b(c[1]), b(c[2]))
}

/// Writes one polyline; consecutive points that print the same (pieces of
/// zero length, where a contour passes through a vertex) are written once,
/// and a polyline left with one point (a line shorter than a hundredth of
/// a pixel) is not written: it draws nothing.
fn push_polyline(s: &mut String, points: &[[f32; 2]], opacity: Option<f32>) {
    let start = s.len();
    s.push_str("<polyline points=\"");
    let (mut here, mut last) = (String::with_capacity(32), String::with_capacity(32));
    let mut written = 0;
    for p in points {
        here.clear();
        push_hundredths(&mut here, p[0]);
        here.push(',');
        push_hundredths(&mut here, p[1]);
        if here == last {
            continue;
        }
        if !last.is_empty() {
            s.push(' ');
        }
        s.push_str(&here);
        written += 1;
        std::mem::swap(&mut here, &mut last);
    }
    if written < 2 {
        s.truncate(start);
        return;
    }
    s.push('"');
    if let Some(o) = opacity.filter(|&o| o < 0.995) {
        let _ = write!(s, " stroke-opacity=\"{o:.2}\"");
    }
    s.push_str("/>\n");
}

/// Writes `x` with two decimals (rounded to the nearest hundredth, as
/// `{:.2}` does but without its exact decimal expansion: a drawing's
/// coordinates differ at most in a tie); a non-finite value as `0.00`.
fn push_hundredths(s: &mut String, x: f32) {
    let h = f64::from(x) * 100.0;
    let h = if h.is_finite() { h.round() as i64 } else { 0 };
    if h < 0 {
        s.push('-');
    }
    let a = h.unsigned_abs();
    let _ = write!(s, "{}.{:02}", a / 100, a % 100);
}

/// An SVG document on a `width` × `height` pixel canvas, written in order:
/// the one SVG writer of shapecue (the line drawings' groups and the
/// strokes' filled outlines alike), with one number format (two decimals,
/// [`push_hundredths`]).
pub struct SvgDocument {
    s: String,
}

impl SvgDocument {
    /// The document's opening tag.
    pub fn new(width: u32, height: u32) -> SvgDocument {
        SvgDocument {
            s: format!(
                "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"{width}\" height=\"{height}\" \
                 viewBox=\"0 0 {width} {height}\">\n"
            ),
        }
    }

    /// A rectangle filling the canvas in `fill` (a CSS colour).
    pub fn background(&mut self, fill: &str) {
        let _ = writeln!(
            self.s,
            "<rect width=\"100%\" height=\"100%\" fill=\"{fill}\"/>"
        );
    }

    /// One group with its id, class, colour and stroke width; round caps
    /// and joins; a polyline's `stroke-opacity` where it is below 1. An
    /// empty layer is kept (as an empty group), so a stylesheet can rely on
    /// every requested cue's group.
    pub fn layer(&mut self, layer: &SvgLayer) {
        let s = &mut self.s;
        let _ = writeln!(
            s,
            "<g id=\"{id}\" class=\"{id}\" fill=\"none\" stroke=\"{c}\" stroke-width=\"{w}\" \
             stroke-linecap=\"round\" stroke-linejoin=\"round\"{dash}>",
            id = layer.id,
            c = hex(layer.color),
            w = layer.stroke_width,
            dash = if layer.dashed {
                format!(
                    " stroke-dasharray=\"{:.1} {:.1}\"",
                    3.0 * layer.stroke_width,
                    2.0 * layer.stroke_width
                )
            } else {
                String::new()
            }
        );
        for l in &layer.lines {
            push_polyline(s, &l.points, Some(l.opacity));
        }
        s.push_str("</g>\n");
    }

    /// A closed outline through `points` (pixels), filled with `fill`.
    pub fn outline(&mut self, points: impl IntoIterator<Item = [f32; 2]>, fill: &str) {
        let s = &mut self.s;
        s.push_str("<path d=\"");
        for (i, [x, y]) in points.into_iter().enumerate() {
            s.push(if i == 0 { 'M' } else { 'L' });
            push_hundredths(s, x);
            s.push(',');
            push_hundredths(s, y);
            s.push(' ');
        }
        let _ = writeln!(s, "Z\" fill=\"{fill}\"/>");
    }

    /// The document's text, closed.
    pub fn finish(mut self) -> String {
        self.s.push_str("</svg>\n");
        self.s
    }
}

/// SVG text of `layers` on a `width` × `height` canvas: one group per
/// layer ([`SvgDocument::layer`]).
pub fn svg_layers_text(layers: &[SvgLayer], width: u32, height: u32) -> String {
    let mut doc = SvgDocument::new(width, height);
    for layer in layers {
        doc.layer(layer);
    }
    doc.finish()
}

/// Writes [`svg_layers_text`] to `path` (whole or not at all).
pub fn write_svg_layers(path: &Path, layers: &[SvgLayer], width: u32, height: u32) -> Result<()> {
    super::output::write_bytes_atomic(path, svg_layers_text(layers, width, height).as_bytes())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn layers_are_groups_with_their_own_id_colour_width_and_opacity() {
        let layers = [
            SvgLayer {
                id: "contours",
                stroke_width: 2.0,
                color: [0.0, 0.0, 0.0],
                lines: vec![SvgPolyline {
                    points: vec![[0.0, 0.0], [1.0, 1.0]],
                    opacity: 1.0,
                }],
                dashed: false,
            },
            SvgLayer {
                id: "suggestive-contours",
                stroke_width: 1.5,
                color: [1.0, 0.5, 0.0],
                lines: vec![SvgPolyline {
                    points: vec![[0.0, 0.0], [1.0, 1.0], [2.0, 0.0]],
                    opacity: 0.5,
                }],
                dashed: true,
            },
        ];
        let t = svg_layers_text(&layers, 8, 8);
        assert!(t.contains("<g id=\"contours\" class=\"contours\" fill=\"none\" stroke=\"#000000\" stroke-width=\"2\""));
        assert!(t.contains("id=\"suggestive-contours\" class=\"suggestive-contours\" fill=\"none\" stroke=\"#ff8000\" stroke-width=\"1.5\""));
        assert!(t.contains("points=\"0.00,0.00 1.00,1.00 2.00,0.00\" stroke-opacity=\"0.50\""));
        assert!(t.contains("points=\"0.00,0.00 1.00,1.00\"/>"));
        // A line shorter than a hundredth of a pixel prints one point: none.
        let mut one = String::new();
        push_polyline(&mut one, &[[3.0, 4.0], [3.001, 4.002]], None);
        assert_eq!(one, "");
        assert!(t.contains("stroke-dasharray=\"4.5 3.0\""));
        assert_eq!(t.matches("stroke-dasharray").count(), 1);
    }
}
