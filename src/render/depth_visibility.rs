//! Which parts of drawn lines are visible in a rendered frame, joined into
//! polylines in image pixels: feature edges (House & Li) and occluding and
//! suggestive contours (DeCarlo et al. 2003), for the SVG writer
//! ([`crate::export::svg`], which re-exports these items) and the edges
//! picture.
//!
//! Joining: contour segments come from faces that share mesh edges, and each
//! endpoint carries the edge it lies on, so two segments are joined exactly
//! when they end on the same edge, never by comparing floats. Pieces cut by
//! occlusion, and feature edges (whose ends are mesh vertices, computed the
//! same way for every edge that meets there), are joined where their pixel
//! positions agree within 1/64 pixel. Pieces are put in a canonical order
//! before joining, so the result does not depend on the order in which the
//! device emitted segments.
//!
//! Visibility: each drawn edge (a non-marker quad of the edge-out buffer) is
//! taken from the midpoints of its quad ends, i.e. the projected edge, and
//! sampled about once per pixel in screen space (NDC depth is affine in screen
//! space along a projected line). A sample is visible when it lies in the image
//! and its window depth is at most the farthest depth of the 3×3 pixels around
//! it (faces beside a crease may be nearer than the edge a fraction of a pixel
//! away) plus `bias` plus the edge's depth change over 1.5 pixels (the stored
//! sample need not sit at the pixel centre). Lines are drawn without writing
//! depth, so the depth buffer holds the surfaces only: a line is hidden by
//! the mesh, never by another line's quad, whatever the stroke width.

use glam::Mat4;

use super::{Frame, clip_segment};
use crate::spec::chains::{ChainPiece, chain};
use crate::spec::feature_lines::{LINE_FREE, Segment, edge_key};
use crate::spec::visibility::NO_FACE;

/// Default depth bias (window depth units) of [`visible_joined`].
pub const DEFAULT_BIAS: f32 = 1e-3;

/// A line to test for visibility: clip-space ends (OpenGL convention, w > 0),
/// the mesh edge each end lies on when known, and an opacity.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ClipLine {
    /// Clip-space ends.
    pub ends: [[f32; 4]; 2],
    /// The mesh edge of each end ([`edge_key`]), when the end lies on one.
    pub edges: [Option<u64>; 2],
    /// Stroke opacity in [0, 1].
    pub opacity: f32,
}

/// How the end of a visible piece is matched with others (the chainer's
/// key: [`chain_key`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
enum EndKey {
    /// The mesh edge it lies on (exact).
    Edge(u64),
    /// Its pixel position in 1/64 pixel.
    Pixel(i64, i64),
}

/// A visible piece in image pixels (origin top left).
#[derive(Clone, Copy, Debug)]
struct Piece {
    ends: [[f32; 2]; 2],
    keys: [EndKey; 2],
    opacity: f32,
}

/// A polyline in image pixels with its opacity.
#[derive(Clone, Debug, PartialEq)]
pub struct SvgPolyline {
    /// Points, origin top left.
    pub points: Vec<[f32; 2]>,
    /// Stroke opacity in [0, 1] (the mean over its pieces).
    pub opacity: f32,
}

fn pixel_key(p: [f32; 2]) -> EndKey {
    EndKey::Pixel((p[0] * 64.0).round() as i64, (p[1] * 64.0).round() as i64)
}

/// The drawn edges of `edge_out` (4 clip-space vertices per edge, House & Li
/// layout) as [`ClipLine`]s: the midpoints of the quad ends, i.e. the
/// projected edge. Marker quads (NaN) and non-finite quads are skipped.
pub fn edge_out_lines(edge_out: &[[f32; 4]]) -> Vec<ClipLine> {
    let mid = |a: [f32; 4], b: [f32; 4]| [0.5 * (a[0] + b[0]), 0.5 * (a[1] + b[1]), a[2], a[3]];
    edge_out
        .chunks_exact(4)
        .filter(|q| !q[0][0].is_nan() && q.iter().flatten().all(|c| c.is_finite()))
        .map(|q| ClipLine {
            ends: [mid(q[0], q[3]), mid(q[1], q[2])],
            edges: [None; 2],
            opacity: 1.0,
        })
        .collect()
}

/// Contour or suggestive-contour segments of `kind` (0 or 1) projected by
/// `view_proj`, each end keeping the mesh edge it lies on. A segment crossing
/// the near plane is cut there (the cut end has no edge); one behind it, or
/// with a non-finite point, is dropped. `opacity` maps a segment's strength
/// to its stroke opacity.
pub fn segment_lines(
    view_proj: Mat4,
    segments: &[Segment],
    kind: u32,
    opacity: impl Fn(f32) -> f32,
) -> Vec<ClipLine> {
    let mut out = Vec::new();
    for s in segments.iter().filter(|s| s.family == kind) {
        let Some((a, b, cut)) = clip_segment(view_proj, s.a, s.b) else {
            continue;
        };
        // A cut end no longer lies on its mesh edge; an end that a line's
        // test cut inside a face never lay on one.
        // An end on no face (a stroke on a distance field) has no edge.
        let edge = |i: usize| {
            (!cut[i] && s.ends[i][0] != LINE_FREE && s.ends[i] != NO_FACE)
                .then(|| edge_key(s.ends[i]))
        };
        out.push(ClipLine {
            ends: [a.to_array(), b.to_array()],
            edges: [edge(0), edge(1)],
            opacity: opacity(s.strength),
        });
    }
    out
}

/// Visible parts of `lines` against the depth of `frame`, joined into
/// polylines (exactly by mesh edge where both ends know theirs, else by pixel
/// position within 1/64 pixel), in a canonical order.
pub fn visible_joined(lines: &[ClipLine], frame: &Frame, bias: f32) -> Vec<SvgPolyline> {
    let mut pieces: Vec<Piece> = Vec::new();
    for l in lines {
        let (s0, s1) = (to_px(l.ends[0], frame), to_px(l.ends[1], frame));
        if !s0.iter().chain(&s1).all(|c| c.is_finite()) {
            continue;
        }
        let len = ((s1[0] - s0[0]).powi(2) + (s1[1] - s0[1]).powi(2)).sqrt();
        let n = (len.ceil() as usize).clamp(1, 1 << 16);
        // The depth buffer holds one (multi)sample per pixel, up to a pixel away
        // from the sample point: allow the line's depth change over 1.5 pixels.
        let bias = bias + 1.5 * (s1[2] - s0[2]).abs() / len.max(1.0);
        let samples = Samples { s0, s1, n };
        let mut start: Option<usize> = None;
        for i in 0..=n {
            let v = visible(samples.at(i), frame, bias);
            match (v, start) {
                (true, None) => start = Some(i),
                (false, Some(s)) => {
                    if i - 1 > s {
                        pieces.push(samples.piece(l, s, i - 1));
                    }
                    start = None;
                }
                _ => {}
            }
        }
        if let Some(s) = start.filter(|&s| s < n) {
            pieces.push(samples.piece(l, s, n));
        }
    }
    join(pieces)
}

/// A clip-space point in image pixels (origin top left), with its window depth.
fn to_px(c: [f32; 4], frame: &Frame) -> [f32; 3] {
    crate::spec::view::clip_to_pixel(c, frame.width, frame.height)
}

/// Whether the pixel point `p` (with its depth) lies in the image and is not
/// behind the depth of `frame` by more than `bias`.
fn visible(p: [f32; 3], frame: &Frame, bias: f32) -> bool {
    let (w, h) = (frame.width as f32, frame.height as f32);
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
            if let Some(d) = frame.depth_at((x + dx).max(0) as u32, (y + dy).max(0) as u32) {
                far = far.max(d);
            }
        }
    }
    p[2] <= far + bias
}

/// A line in pixels, from `s0` to `s1`, sampled at `n + 1` points.
struct Samples {
    s0: [f32; 3],
    s1: [f32; 3],
    n: usize,
}

impl Samples {
    /// Sample `i` of the line.
    fn at(&self, i: usize) -> [f32; 3] {
        let (s0, s1) = (self.s0, self.s1);
        let t = i as f32 / self.n as f32;
        [
            s0[0] + t * (s1[0] - s0[0]),
            s0[1] + t * (s1[1] - s0[1]),
            s0[2] + t * (s1[2] - s0[2]),
        ]
    }

    /// The visible piece of line `l` from sample `s` to sample `e`. A piece
    /// end keeps the line's mesh edge only where it is the line's own end;
    /// ends cut by occlusion are matched by position.
    fn piece(&self, l: &ClipLine, s: usize, e: usize) -> Piece {
        let (a, b) = (self.at(s), self.at(e));
        let (a, b) = ([a[0], a[1]], [b[0], b[1]]);
        let key = |i: usize, p: [f32; 2], own: Option<u64>| match own {
            Some(k) if i == 0 || i == self.n => EndKey::Edge(k),
            _ => pixel_key(p),
        };
        Piece {
            ends: [a, b],
            keys: [key(s, a, l.edges[0]), key(e, b, l.edges[1])],
            opacity: l.opacity,
        }
    }
}

/// The chainer's key of a piece end: its mesh edge, or its pixel
/// position (in 1/64 pixel) as a point.
fn chain_key(k: EndKey) -> crate::spec::chains::EndKey {
    use crate::spec::chains::EndKey as C;
    match k {
        EndKey::Edge(e) => C::Edge((e >> 32) as u32, e as u32),
        EndKey::Pixel(x, y) => C::Point([x, y, 0]),
    }
}

/// Joins pieces sharing end keys into polylines with the one chainer of
/// both visibility methods ([`crate::spec::chains::chain`]): chains start
/// at ends not shared by exactly two pieces, then closed loops remain; at
/// a branch a chain goes on along the first piece in canonical order. The
/// pieces are first sorted (by keys, then coordinates) and numbered in that
/// order, so the result does not depend on their input order.
fn join(mut pieces: Vec<Piece>) -> Vec<SvgPolyline> {
    let order = |p: &Piece| {
        let mut k = p.keys;
        k.sort();
        k
    };
    pieces.sort_by(|a, b| {
        order(a).cmp(&order(b)).then_with(|| {
            let fa = a.ends.as_flattened();
            let fb = b.ends.as_flattened();
            fa.iter()
                .zip(fb)
                .map(|(x, y)| x.total_cmp(y))
                .find(|o| o.is_ne())
                .unwrap_or(std::cmp::Ordering::Equal)
        })
    });
    let keyed: Vec<ChainPiece> = (pieces.iter().enumerate())
        .map(|(i, p)| ChainPiece {
            layer: 0,
            visible: true,
            seg: i as u32,
            t: [0.0, 1.0],
            keys: p.keys.map(chain_key),
        })
        .collect();
    (chain(&keyed).into_iter())
        .map(|c| {
            let mut points = Vec::with_capacity(c.pieces.len() + 1);
            let mut opacity = 0.0;
            for (k, &(i, reversed)) in c.pieces.iter().enumerate() {
                let p = &pieces[i as usize];
                let [a, b] = if reversed {
                    [p.ends[1], p.ends[0]]
                } else {
                    p.ends
                };
                if k == 0 {
                    points.push(a);
                }
                points.push(b);
                opacity += p.opacity;
            }
            SvgPolyline {
                points,
                opacity: opacity / c.pieces.len() as f32,
            }
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn piece(a: [f32; 2], b: [f32; 2], ka: EndKey, kb: EndKey) -> Piece {
        Piece {
            ends: [a, b],
            keys: [ka, kb],
            opacity: 1.0,
        }
    }

    #[test]
    fn pieces_ending_on_the_same_mesh_edge_join_although_their_floats_differ() {
        // Three segments of an open contour whose shared crossings differ by
        // rounding (each face interpolates from its own corner).
        let e = EndKey::Edge;
        let ps = vec![
            piece([2.0, 0.0], [1.0, 0.0], e(2), e(1)),
            piece([0.0, 0.0], [1.0001, 0.0], e(0), e(1)),
            piece([2.0002, 0.0], [3.0, 0.0], e(2), e(3)),
        ];
        let mut lines = join(ps.clone());
        assert_eq!(lines.len(), 1, "{lines:?}");
        let l = lines.pop().unwrap();
        assert_eq!(l.points.len(), 4);
        // The same polyline whatever the input order.
        let mut rev = ps;
        rev.reverse();
        assert_eq!(join(rev), vec![l]);
    }

    #[test]
    fn pieces_on_different_edges_stay_apart_even_when_their_ends_coincide() {
        let e = EndKey::Edge;
        let ps = vec![
            piece([0.0, 0.0], [1.0, 0.0], e(0), e(1)),
            piece([1.0, 0.0], [2.0, 0.0], e(2), e(3)),
        ];
        assert_eq!(join(ps).len(), 2);
    }

    #[test]
    fn a_closed_loop_becomes_one_polyline_and_branches_end_chains() {
        let e = EndKey::Edge;
        let sq = vec![
            piece([0.0, 0.0], [1.0, 0.0], e(0), e(1)),
            piece([1.0, 0.0], [1.0, 1.0], e(1), e(2)),
            piece([1.0, 1.0], [0.0, 1.0], e(2), e(3)),
            piece([0.0, 1.0], [0.0, 0.0], e(3), e(0)),
        ];
        let l = join(sq);
        assert_eq!(l.len(), 1);
        assert_eq!(l[0].points.len(), 5);
        assert_eq!(l[0].points.first(), l[0].points.last());
        // Three pieces meeting at one end: one chain passes it, the third
        // piece is a polyline of its own.
        let y = vec![
            piece([0.0, 0.0], [1.0, 0.0], e(0), e(9)),
            piece([1.0, 0.0], [2.0, 0.0], e(9), e(1)),
            piece([1.0, 0.0], [1.0, 1.0], e(9), e(2)),
        ];
        let l = join(y);
        assert_eq!(l.len(), 2, "{l:?}");
        assert_eq!(l.iter().map(|p| p.points.len()).sum::<usize>(), 5);
    }

    #[test]
    fn an_occluder_cuts_a_line_and_only_its_own_ends_keep_their_edges() {
        // 16×4 image, depth 0.5 everywhere but a near block over columns 6..10.
        let (w, h) = (16u32, 4u32);
        let mut depth = vec![0.5f32; (w * h) as usize];
        for y in 0..h {
            for x in 6..10 {
                depth[(y * w + x) as usize] = 0.1;
            }
        }
        let frame = Frame {
            width: w,
            height: h,
            rgba: vec![0; (4 * w * h) as usize],
            depth,
        };
        // A horizontal line across the image at window depth 0.5 (NDC z 0).
        let line = ClipLine {
            ends: [[-0.95, 0.0, 0.0, 1.0], [0.95, 0.0, 0.0, 1.0]],
            edges: [Some(7), Some(8)],
            opacity: 1.0,
        };
        let next = ClipLine {
            ends: [[0.95, 0.0, 0.0, 1.0], [0.95, 0.9, 0.0, 1.0]],
            edges: [Some(8), Some(11)],
            opacity: 1.0,
        };
        let l = visible_joined(&[line, next], &frame, DEFAULT_BIAS);
        // Two visible pieces of the first line; the right one joins the second
        // line through edge 8.
        assert_eq!(l.len(), 2, "{l:?}");
        let lens: Vec<usize> = l.iter().map(|p| p.points.len()).collect();
        assert!(lens.contains(&2) && lens.contains(&3), "{lens:?}");
        for p in &l {
            // Pixels 7 and 8 are hidden (their 3×3 neighbourhoods are all near).
            assert!(
                p.points.iter().all(|q| !(q[0] > 7.0 && q[0] < 9.0)),
                "{p:?}"
            );
        }
    }
}
