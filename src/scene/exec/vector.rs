//! The vector drawing of one view with exact visibility: the segments the
//! SVG draws ([`gather`]: the drawn line families' segments, then the
//! drawn feature edges), split where their visibility changes by the
//! `visibility` family over the mesh's BVH, joined into chains
//! ([`crate::spec::chains`]), and the SVG groups of those chains
//! ([`svg_layers_exact`]): one polyline per chain, in the same groups, ids
//! and styles as the depth-buffer method's ([`super::draw::svg_layers`]).

use crate::error::Result;
use crate::export::svg::{SvgLayer, SvgPolyline};
use crate::render::Camera;
use crate::scene::file::{Effects, LineStyle, Scene};
use crate::scene::planner::Cue;
use crate::spec::chains::{Chain, ChainPiece, chain, chain_pieces};
use crate::spec::edges::{EdgeOutput, KIND_DRAWN};
use crate::spec::feature_lines::{Hidden, LineFamily, Segment, hidden_id};
use crate::spec::sdf_lines::Stroke;
use crate::spec::view::View;
use crate::spec::view::project_to_pixel as pixel;
use crate::spec::visibility::{Faces, NO_FACE, Pieces, VisibilityOptions};
use crate::spec::visibility_plan::RayPlan;
use crate::stages::bvh::Bvh;
use crate::stages::visibility::{Classified, classify_planned, spatial_order};

pub use crate::spec::feature_lines::{LAYER_FEATURE_EDGES, LAYER_INTERSECTIONS, LAYER_STROKES};

/// The centre lines of `strokes` (scene frame) as segments of the strokes'
/// layer, each point moved `lift` towards the eye of `view` (the strokes
/// lie on the interpolated surface, which marching cubes cuts as chords:
/// half a voxel lifts them off the chords that would hide them), their
/// ends on no face of the mesh ([`NO_FACE`]).
pub(super) fn stroke_segments(strokes: &[Stroke], view: &View, lift: f32) -> Vec<Segment> {
    let eye = view.eye;
    let towards = |p: &[f64; 3]| -> [f32; 3] {
        let q = glam::Vec3::new(p[0] as f32, p[1] as f32, p[2] as f32);
        let d = if view.ortho {
            -view.unit_dir()
        } else {
            eye - q
        };
        (q + lift * d.normalize_or_zero()).to_array()
    };
    let mut out = Vec::new();
    for st in strokes {
        let pts: Vec<[f32; 3]> = st.points.iter().map(towards).collect();
        for w in pts.windows(2) {
            out.push(Segment::new(
                w[0],
                w[1],
                LAYER_STROKES,
                1.0,
                [NO_FACE, NO_FACE],
            ));
        }
    }
    out
}

/// Whether a segment is drawn at all: one of no strength (faded out, or a
/// non-finite test) is not, in the image nor in the SVG.
pub(super) fn shown(s: &Segment) -> bool {
    s.strength > 0.0
}

/// Every line family a scene draws, in drawing order (contours, suggestive
/// contours, then the curvature line cues in family order), each with its
/// stroke and whether its strength fades it: suggestive contours always
/// (DeCarlo et al. fade them out as they approach the contour generator,
/// where they are unstable), the curvature line families when `[lines]`
/// fades them, contours never.
pub(super) fn line_styles(fx: &Effects) -> Vec<(LineStyle, bool)> {
    let hidden = |f: LineFamily| {
        fx.lines
            .styles
            .iter()
            .find(|s| s.family == f)
            .map_or(Hidden::Remove, |s| s.hidden)
    };
    let mut out = Vec::new();
    for (cue, family, (width, color), faded) in [
        (Cue::Contours, LineFamily::Contours, fx.contour, false),
        (
            Cue::SuggestiveContours,
            LineFamily::Suggestive,
            fx.suggestive,
            true,
        ),
    ] {
        if fx.cues.contains(&cue) {
            let style = LineStyle {
                family,
                width,
                color,
                hidden: hidden(family),
            };
            out.push((style, faded));
        }
    }
    let fade = fx.lines.curves.fade;
    out.extend(fx.lines.styles_for(&fx.cues).into_iter().map(|s| (s, fade)));
    out
}

/// The stroke width of the curvature-directed strokes' SVG polylines, in
/// pixels (their tapered strips are the frame's and the strokes command's
/// `--svg` outlines).
pub const STROKE_PX: f32 = 1.5;

/// The lines of one view, classified and chained.
#[derive(Clone, Debug, Default)]
pub struct VisibleLines {
    /// The classified segments: the drawn families' segments, then the
    /// drawn feature edges (ends at mesh vertices `[v, v]`, kind
    /// [`LAYER_FEATURE_EDGES`], strength 1).
    pub segments: Vec<Segment>,
    /// The faces each segment lies on (at most four; left out of its
    /// queries).
    pub faces: Vec<Faces>,
    /// The pieces of each segment, `(t0, t1, visible)`.
    pub pieces: Vec<Pieces>,
    /// Every piece of every segment, as chained.
    pub chain_pieces: Vec<ChainPiece>,
    /// The chains (one SVG polyline each).
    pub chains: Vec<Chain>,
}

impl VisibleLines {
    /// The pieces as NPZ-ready arrays ([`crate::export::npz`]): one row
    /// per piece (the coordinates of the segments), its segment's family or
    /// layer code (a [`crate::spec::feature_lines::LineFamily`] as `u32`,
    /// or the feature edges', intersection lines' or strokes' layer),
    /// strength, visibility, the faces it lies on (`-1` past the last), its
    /// chain, and the face of the mesh (`positions`, `faces`, in the
    /// segments' coordinates) it lies in with each end's barycentric
    /// coordinates there ([`crate::mesh::barycentric::face_of_segment`];
    /// `-1` and zeros for a line on no face).
    pub fn arrays(
        &self,
        positions: &[[f64; 3]],
        faces: &[[u32; 3]],
    ) -> crate::export::npz::SegmentArrays {
        let chain_of = self.chain_of_pieces();
        let mut out = crate::export::npz::SegmentArrays::default();
        let wide = |p: [f32; 3]| p.map(f64::from);
        for (i, p) in self.chain_pieces.iter().enumerate() {
            let s = &self.segments[p.seg as usize];
            let (a, b) = (self.point(p.seg, p.t[0]), self.point(p.seg, p.t[1]));
            let f = &self.faces[p.seg as usize];
            let on =
                crate::mesh::barycentric::face_of_segment((wide(a), wide(b)), f, positions, faces);
            out.face.push(on.map_or(-1, |o| i64::from(o.0)));
            out.bary
                .push(on.map_or([[0.0; 3]; 2], |o| o.1.map(|w| w.map(|x| x as f32))));
            out.a.push(a);
            out.b.push(b);
            out.family.push(s.family);
            out.strength.push(s.strength);
            out.visible.push(u8::from(p.visible));
            out.faces.push(std::array::from_fn(|k| {
                f.get(k).map_or(-1, |&x| i64::from(x))
            }));
            out.chain.push(chain_of[i]);
        }
        out
    }

    /// The point at `t` of segment `seg`.
    pub fn point(&self, seg: u32, t: f32) -> [f32; 3] {
        let s = &self.segments[seg as usize];
        std::array::from_fn(|k| s.a[k] + t * (s.b[k] - s.a[k]))
    }

    /// The points of a chain, in walking order.
    pub fn chain_points(&self, c: &Chain) -> Vec<[f32; 3]> {
        let mut out = Vec::with_capacity(c.pieces.len() + 1);
        for (n, &(i, reversed)) in c.pieces.iter().enumerate() {
            let p = &self.chain_pieces[i as usize];
            let (from, to) = if reversed {
                (p.t[1], p.t[0])
            } else {
                (p.t[0], p.t[1])
            };
            if n == 0 {
                out.push(self.point(p.seg, from));
            }
            out.push(self.point(p.seg, to));
        }
        out
    }

    /// Mean pieces per visible chain (0 without one).
    pub fn mean_chain_length(&self) -> f64 {
        crate::spec::chains::mean_length(self.chains.iter().filter(|c| c.visible))
    }

    /// The chain of each piece of [`VisibleLines::chain_pieces`].
    pub fn chain_of_pieces(&self) -> Vec<u32> {
        let mut chain_of = vec![0u32; self.chain_pieces.len()];
        for (c, ch) in self.chains.iter().enumerate() {
            for &(i, _) in &ch.pieces {
                chain_of[i as usize] = c as u32;
            }
        }
        chain_of
    }

    /// The same lines moved by `shift` (scene frame to world).
    pub(super) fn shifted(&self, shift: [f64; 3]) -> VisibleLines {
        let mv = |p: [f32; 3]| -> [f32; 3] {
            std::array::from_fn(|i| (f64::from(p[i]) + shift[i]) as f32)
        };
        VisibleLines {
            segments: (self.segments.iter())
                .map(|s| Segment {
                    a: mv(s.a),
                    b: mv(s.b),
                    ..*s
                })
                .collect(),
            ..self.clone()
        }
    }
}

/// The segments the SVG draws, each its layer its kind: the shown segments
/// of the families the scene draws, then the drawn feature edges of `edges`
/// (the edge stage's output and each edge entry's two vertices) between
/// the `positions` of their vertices.
pub(super) fn gather(
    fx: &Effects,
    segs: &[Segment],
    edges: Option<(&EdgeOutput, &[[u32; 2]])>,
    positions: &[[f32; 3]],
) -> Vec<Segment> {
    let kinds: Vec<u32> = line_styles(fx).iter().map(|s| s.0.family as u32).collect();
    let mut out: Vec<Segment> = (segs.iter())
        .filter(|s| kinds.contains(&s.family) && shown(s))
        .copied()
        .collect();
    if let Some((eo, pairs)) = edges {
        for (k, pair) in eo.kind.iter().zip(pairs) {
            if k & KIND_DRAWN == 0 {
                continue;
            }
            let [a, b] = *pair;
            let (pa, pb) = (positions[a as usize], positions[b as usize]);
            out.push(Segment::new(
                pa,
                pb,
                LAYER_FEATURE_EDGES,
                1.0,
                [[a, a], [b, b]],
            ));
        }
    }
    out
}

/// Classifies `segments` seen in `view` over the mesh (`positions`, `faces`)
/// whose tree `bvh` holds, and chains the pieces; `scale` is the scene's
/// size (for the keys of ends inside faces). The pieces move into the
/// [`VisibleLines`]: the [`Classified`] keeps the counts and the timing.
pub(super) fn classify_view(
    bvh: &mut Bvh,
    mesh: (&[[f32; 3]], &[[u32; 3]]),
    segments: Vec<Segment>,
    view: &View,
    scale: f32,
) -> Result<(VisibleLines, Classified)> {
    let (positions, faces) = mesh;
    let opts = VisibilityOptions::default();
    // Classified (and kept) in the Morton order of their midpoints: the
    // queries of neighbouring work-items walk the same part of the tree.
    let order = spatial_order(&segments);
    let segments: Vec<Segment> = order.iter().map(|&i| segments[i]).collect();
    let plan = RayPlan::new(positions, faces, &segments, view, &opts)?;
    let mut c = classify_planned(bvh, &plan)?;
    let chain_pieces = chain_pieces(&segments, &c.pieces, scale);
    let chains = chain(&chain_pieces);
    let vis = VisibleLines {
        segments,
        faces: plan.segs.iter().map(|s| s.exclude).collect(),
        pieces: std::mem::take(&mut c.pieces),
        chain_pieces,
        chains,
    };
    Ok((vis, c))
}

/// The SVG groups of one view from its chains: for each line family the
/// scene draws ([`line_styles`]) its hidden chains (as its style asks) under
/// its visible ones, then the visible feature edges; one polyline per
/// chain. A faded family's polyline has its pieces' mean strength as its
/// opacity.
pub(super) fn svg_layers_exact(scene: &Scene, cam: &Camera, vis: &VisibleLines) -> Vec<SvgLayer> {
    let fx = &scene.effects;
    let [w, h] = scene.size;
    let vp = cam.view_proj(w as f32 / h as f32);
    let mut layers = Vec::new();
    for (st, faded) in line_styles(fx) {
        if st.hidden != Hidden::Remove {
            let opacity = if st.hidden == Hidden::Faded { 0.3 } else { 1.0 };
            layers.push(SvgLayer {
                id: hidden_id(st.family),
                stroke_width: 0.5 * st.width,
                color: st.color,
                lines: polylines(vis, st.family as u32, false, vp, [w, h], |_| opacity),
                dashed: st.hidden == Hidden::Dashed,
            });
        }
        layers.push(family_layer(vis, &st, faded, vp, [w, h]));
    }
    for (cue, id, (stroke_width, color), layer) in other_groups(fx) {
        if fx.cues.contains(&cue) {
            layers.push(SvgLayer {
                id,
                stroke_width,
                color,
                lines: polylines(vis, layer, true, vp, [w, h], |_| 1.0),
                dashed: false,
            });
        }
    }
    layers
}

/// An SVG group after the line families: its cue, id, stroke (width in
/// pixels, colour) and layer.
pub(super) type Group = (Cue, &'static str, (f32, [f32; 3]), u32);

/// The SVG groups after the line families, in drawing order: each one's
/// cue, id, stroke (width in pixels, colour) and layer. Both visibility
/// methods write them ([`svg_layers_exact`], `draw::svg_layers`).
pub(super) fn other_groups(fx: &Effects) -> [Group; 3] {
    [
        (
            Cue::CurvatureStrokes,
            "curvature-strokes",
            (STROKE_PX, fx.strokes.color),
            LAYER_STROKES,
        ),
        (
            Cue::IntersectionLines,
            "intersection-lines",
            fx.intersection,
            LAYER_INTERSECTIONS,
        ),
        (
            Cue::FeatureEdges,
            "feature-edges",
            fx.edge,
            LAYER_FEATURE_EDGES,
        ),
    ]
}

/// A family's visible group.
fn family_layer(
    vis: &VisibleLines,
    st: &LineStyle,
    faded: bool,
    vp: glam::Mat4,
    size: [u32; 2],
) -> SvgLayer {
    let strength = |c: &Chain| -> f32 {
        if !faded {
            return 1.0;
        }
        let sum: f32 = (c.pieces.iter())
            .map(|&(i, _)| {
                let seg = vis.chain_pieces[i as usize].seg;
                vis.segments[seg as usize].strength.clamp(0.0, 1.0)
            })
            .sum();
        sum / c.pieces.len().max(1) as f32
    };
    SvgLayer {
        id: st.family.name(),
        stroke_width: st.width,
        color: st.color,
        lines: polylines(vis, st.family as u32, true, vp, size, strength),
        dashed: false,
    }
}

/// The polylines (image pixels) of the chains of `layer` of one
/// visibility, each with `opacity(chain)`; a chain with a point behind the
/// eye is cut there.
fn polylines(
    vis: &VisibleLines,
    layer: u32,
    visible: bool,
    vp: glam::Mat4,
    [w, h]: [u32; 2],
    opacity: impl Fn(&Chain) -> f32,
) -> Vec<SvgPolyline> {
    let mut out = Vec::new();
    for c in (vis.chains.iter()).filter(|c| c.layer == layer && c.visible == visible) {
        let o = opacity(c);
        let mut run: Vec<[f32; 2]> = Vec::new();
        for p in vis.chain_points(c) {
            match pixel(vp, p, w, h) {
                Some(q) => run.push(q),
                None => flush(&mut out, &mut run, o),
            }
        }
        flush(&mut out, &mut run, o);
    }
    out
}

/// Ends the polyline in `run` (two points or more) into `out`.
fn flush(out: &mut Vec<SvgPolyline>, run: &mut Vec<[f32; 2]>, opacity: f32) {
    let points = std::mem::take(run);
    if points.len() >= 2 {
        out.push(SvgPolyline { points, opacity });
    }
}
