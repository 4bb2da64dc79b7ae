//! SVG export of drawn feature edges (edges stage, House & Li): the visible
//! part of each edge, found against the rendered depth buffer, with connected
//! visible pieces joined into polylines.
//!
//! Visibility: each drawn edge (a non-marker quad of the edge-out buffer) is
//! taken from the midpoints of its quad ends, i.e. the projected edge, and
//! sampled about once per pixel in screen space (NDC depth is affine in screen
//! space along a projected line). A sample is visible when it lies in the image
//! and its window depth is at most the farthest depth of the 3×3 pixels around
//! it (faces beside a crease may be nearer than the edge a fraction of a pixel
//! away) plus `bias` plus
//! the edge's depth change over 1.5 pixels (the stored sample need not sit
//! at the pixel centre); the
//! edge quads were drawn into that depth buffer, so an unoccluded edge sees its
//! own depth there.

use std::collections::HashMap;
use std::fmt::Write as _;
use std::path::Path;

use crate::error::Result;
use crate::render::Frame;

/// Default depth bias (window depth units) of [`visible_polylines`].
pub const DEFAULT_BIAS: f32 = 1e-3;

/// Visible pieces of the drawn edges of `edge_out` (4 clip-space vertices per
/// edge, House & Li layout), in image pixel coordinates (origin top left),
/// joined into polylines where pieces share an end point (within 1/64 pixel).
pub fn visible_polylines(edge_out: &[[f32; 4]], frame: &Frame, bias: f32) -> Vec<Vec<[f32; 2]>> {
    let (w, h) = (frame.width as f32, frame.height as f32);
    let to_px = |a: [f32; 4], b: [f32; 4]| {
        // Midpoint of the two quad vertices at one end (same w): the edge end.
        let (x, y, z, cw) = (0.5 * (a[0] + b[0]), 0.5 * (a[1] + b[1]), a[2], a[3]);
        [
            (x / cw * 0.5 + 0.5) * w,
            (0.5 - y / cw * 0.5) * h,
            z / cw * 0.5 + 0.5,
        ]
    };
    let mut pieces: Vec<[[f32; 2]; 2]> = Vec::new();
    for q in edge_out.chunks_exact(4) {
        if q[0][0].is_nan() || !q.iter().flatten().all(|c| c.is_finite()) {
            continue;
        }
        let (s0, s1) = (to_px(q[0], q[3]), to_px(q[1], q[2]));
        let len = ((s1[0] - s0[0]).powi(2) + (s1[1] - s0[1]).powi(2)).sqrt();
        let n = (len.ceil() as usize).clamp(1, 1 << 16);
        // The depth buffer holds one (multi)sample per pixel, up to a pixel away
        // from the sample point: allow the edge's depth change over 1.5 pixels.
        let bias = bias + 1.5 * (s1[2] - s0[2]).abs() / len.max(1.0);
        let at = |i: usize| {
            let t = i as f32 / n as f32;
            [
                s0[0] + t * (s1[0] - s0[0]),
                s0[1] + t * (s1[1] - s0[1]),
                s0[2] + t * (s1[2] - s0[2]),
            ]
        };
        let visible = |p: [f32; 3]| {
            let (x, y) = (p[0].floor(), p[1].floor());
            if !(x >= 0.0 && y >= 0.0 && x < w && y < h) {
                return false;
            }
            // The faces beside a crease can be nearer than the edge a fraction of
            // a pixel away (the mesh's polygon offset is only a slope's worth):
            // the farthest depth of the 3×3 neighbourhood decides.
            let (x, y) = (x as i64, y as i64);
            let mut far = 0f32;
            for dy in -1..=1 {
                for dx in -1..=1 {
                    if let Some(d) = frame.depth_at((x + dx).max(0) as u32, (y + dy).max(0) as u32)
                    {
                        far = far.max(d);
                    }
                }
            }
            p[2] <= far + bias
        };
        let mut start: Option<usize> = None;
        for i in 0..=n {
            let v = visible(at(i));
            match (v, start) {
                (true, None) => start = Some(i),
                (false, Some(s)) => {
                    if i - 1 > s {
                        let (a, b) = (at(s), at(i - 1));
                        pieces.push([[a[0], a[1]], [b[0], b[1]]]);
                    }
                    start = None;
                }
                _ => {}
            }
        }
        if let Some(s) = start.filter(|&s| s < n) {
            let (a, b) = (at(s), at(n));
            pieces.push([[a[0], a[1]], [b[0], b[1]]]);
        }
    }
    join(&pieces)
}

/// Joins segments sharing end points into polylines: chains start at points
/// that are not shared by exactly two segments, then closed loops remain.
fn join(pieces: &[[[f32; 2]; 2]]) -> Vec<Vec<[f32; 2]>> {
    let key = |p: [f32; 2]| ((p[0] * 64.0).round() as i64, (p[1] * 64.0).round() as i64);
    let mut at: HashMap<(i64, i64), Vec<usize>> = HashMap::new();
    for (i, s) in pieces.iter().enumerate() {
        at.entry(key(s[0])).or_default().push(i);
        at.entry(key(s[1])).or_default().push(i);
    }
    let mut used = vec![false; pieces.len()];
    let mut lines = Vec::new();
    let walk = |first: usize, from_end: usize, used: &mut Vec<bool>| {
        let mut line = vec![pieces[first][from_end], pieces[first][1 - from_end]];
        used[first] = true;
        loop {
            let tip = *line.last().expect("non-empty");
            let next = at[&key(tip)].iter().copied().find(|&j| !used[j]);
            let Some(j) = next else { break };
            used[j] = true;
            let far = if key(pieces[j][0]) == key(tip) { 1 } else { 0 };
            line.push(pieces[j][far]);
        }
        line
    };
    for i in 0..pieces.len() {
        for end in 0..2 {
            if !used[i] && at[&key(pieces[i][end])].len() != 2 {
                lines.push(walk(i, end, &mut used));
            }
        }
    }
    for i in 0..pieces.len() {
        if !used[i] {
            lines.push(walk(i, 0, &mut used));
        }
    }
    lines
}

/// SVG text of `polylines` on a `width` × `height` canvas, black round-joined
/// strokes of `stroke_width` pixels.
pub fn svg_text(polylines: &[Vec<[f32; 2]>], width: u32, height: u32, stroke_width: f32) -> String {
    let mut s = format!(
        "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"{width}\" height=\"{height}\" \
         viewBox=\"0 0 {width} {height}\">\n<g fill=\"none\" stroke=\"black\" \
         stroke-width=\"{stroke_width}\" stroke-linecap=\"round\" stroke-linejoin=\"round\">\n"
    );
    for l in polylines {
        s.push_str("<polyline points=\"");
        for (i, p) in l.iter().enumerate() {
            let sep = if i == 0 { "" } else { " " };
            let _ = write!(s, "{sep}{:.2},{:.2}", p[0], p[1]);
        }
        s.push_str("\"/>\n");
    }
    s.push_str("</g>\n</svg>\n");
    s
}

/// Writes [`svg_text`] to `path`.
pub fn write_svg(
    path: &Path,
    polylines: &[Vec<[f32; 2]>],
    width: u32,
    height: u32,
    stroke_width: f32,
) -> Result<()> {
    super::output::write_bytes_atomic(
        path,
        svg_text(polylines, width, height, stroke_width).as_bytes(),
    )
}
