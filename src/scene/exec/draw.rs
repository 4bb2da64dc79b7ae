//! Drawing and outputs: the scene's cameras resolved against the first
//! pose's bounds, the mesh colours and style, the line and edge quads, and
//! the PNG and SVG files of one view.

use crate::error::Result;
use crate::render::colormap::{curvature_color, with_ao};
use crate::render::edges::draw_edges;
use crate::render::{Camera, Frame, MeshStyle, Placement, Renderer, framed};
use crate::scene::file::{CameraKind, Scene, ViewSpec};
use crate::scene::planner::{Cue, Pass, Plan};
use crate::spec::edges::EdgeOutput;
use crate::spec::feature_lines::Segment;
use crate::spec::sdf_lines::Stroke;
use std::path::PathBuf;

/// Host copies of the pose that the renderer and the host-side passes use,
/// relative to the scene origin.
#[derive(Default)]
pub(super) struct PoseData {
    pub(super) pos: Vec<[f32; 3]>,
    pub(super) nrm: Vec<[f32; 3]>,
    pub(super) k: Vec<[f32; 2]>,
    pub(super) ao: Vec<f32>,
}

/// Resolves a view against the scene bounds (scene frame); explicit eyes and
/// targets are world positions, moved into the scene frame by `origin`.
pub(super) fn camera(
    v: &ViewSpec,
    bounds: ([f64; 3], [f64; 3]),
    aspect: f32,
    origin: [f64; 3],
) -> Result<Camera> {
    let local = |p: [f32; 3]| -> glam::Vec3 {
        glam::Vec3::from(std::array::from_fn::<f32, 3, _>(|i| {
            (f64::from(p[i]) - origin[i]) as f32
        }))
    };
    let up = v.up.map(glam::Vec3::from);
    let (placement, target) = match &v.kind {
        CameraKind::LookAt { eye, target } => (Placement::At(local(*eye)), target.map(local)),
        CameraKind::Fit(d) => (Placement::Fit(glam::Vec3::from(*d)), None),
    };
    framed(placement, target, up, v.fov, v.ortho, bounds, aspect)
}

/// Bounds of the vertices that faces use (a stray unreferenced vertex far
/// away must not shrink the mesh to a dot in a fitted camera).
pub(super) fn bounds_of(p: impl Iterator<Item = [f64; 3]>, used: &[bool]) -> ([f64; 3], [f64; 3]) {
    let mut lo = [f64::INFINITY; 3];
    let mut hi = [f64::NEG_INFINITY; 3];
    for (q, _) in p.zip(used).filter(|(_, u)| **u) {
        for i in 0..3 {
            lo[i] = lo[i].min(q[i]);
            hi[i] = hi[i].max(q[i]);
        }
    }
    (lo, hi)
}

/// Centre of bounds (0 on an axis where it is not finite, e.g. no used vertex).
pub(super) fn centre((lo, hi): ([f64; 3], [f64; 3])) -> [f64; 3] {
    std::array::from_fn(|i| {
        let c = 0.5 * (lo[i] + hi[i]);
        if c.is_finite() { c } else { 0.0 }
    })
}

/// Per-vertex colours: curvature colours and/or AO; empty (the style's flat
/// colour) when neither is asked for.
pub(super) fn mesh_colors(
    scene: &Scene,
    plan: &Plan,
    pose: &PoseData,
    scale: f32,
) -> Vec<[f32; 3]> {
    let fx = &scene.effects;
    let colors = fx.cues.contains(&Cue::CurvatureColors);
    // The AO pass is planned exactly when the AO cue is asked for.
    let ao = plan.contains(Pass::Ao);
    if !colors && !ao {
        return Vec::new();
    }
    (0..pose.pos.len())
        .map(|i| {
            let c = if colors {
                let [a, b] = pose.k[i];
                curvature_color(a, b, scale, fx.base_color)
            } else {
                fx.base_color
            };
            if ao { with_ao(c, pose.ao[i]) } else { c }
        })
        .collect()
}

/// The opacity bin (0..4) of a suggestive-contour segment's strength in [0, 1].
fn strength_bin(strength: f32) -> usize {
    if strength.is_finite() {
        ((strength.clamp(0.0, 1.0) * 4.0).ceil() as usize).clamp(1, 4) - 1
    } else {
        3
    }
}

/// What one view draws on top of the mesh.
pub(super) struct ViewLines<'a> {
    /// Contour and suggestive-contour segments (scene frame).
    pub(super) segments: &'a [Segment],
    /// The edge stage's outputs, when feature edges are planned.
    pub(super) edges: Option<&'a EdgeOutput>,
    /// Curvature-directed strokes (scene frame).
    pub(super) strokes: &'a [Stroke],
    /// Lift of the strokes towards the eye (world units).
    pub(super) stroke_lift: f32,
}

/// Draws one view (the mesh the renderer holds, line quads, edge quads),
/// reads it back and writes its images to `paths`. Returns the contour and
/// suggestive-contour segments drawn, and the image read back (with depth
/// when an SVG was asked for).
pub(super) fn draw_view(
    renderer: &mut Renderer,
    scene: &Scene,
    plan: &Plan,
    cam: &Camera,
    lines: ViewLines<'_>,
    paths: &[&PathBuf],
) -> Result<([usize; 2], Frame)> {
    let fx = &scene.effects;
    let [w, h] = scene.size;
    renderer.begin(cam)?;
    let lines_only = !(plan.contains(Pass::Ao)
        || fx.cues.contains(&Cue::Shading)
        || fx.cues.contains(&Cue::CurvatureColors));
    let style = if lines_only {
        // Lines only: the mesh is drawn flat in the background colour,
        // so that it hides the lines behind it.
        MeshStyle {
            ambient: 1.0,
            color: scene.background,
            ..MeshStyle::default()
        }
    } else {
        MeshStyle {
            ambient: fx.ambient,
            color: fx.base_color,
            ..MeshStyle::default()
        }
    };
    renderer.draw_uploaded(style)?;
    let mut drawn = [0usize; 2];
    // Contours opaque; suggestive contours in four opacity bins of
    // their n·v fade (DeCarlo et al. fade them out as they approach
    // the contour generator, where they are unstable).
    const BINS: [f32; 4] = [0.25, 0.5, 0.75, 1.0];
    for (kind, (width, color)) in [(0u32, fx.contour), (1u32, fx.suggestive)] {
        let mut n = 0;
        for (bi, &alpha) in BINS.iter().enumerate() {
            let pts: Vec<[f32; 3]> = lines
                .segments
                .iter()
                .filter(|s| s.2 == kind && (kind == 0 || strength_bin(s.3) == bi))
                .flat_map(|s| [s.0, s.1])
                .collect();
            if pts.is_empty() || (kind == 0 && bi > 0) {
                continue;
            }
            n += pts.len() / 2;
            let [r, g, b] = color;
            let a = if kind == 0 { 1.0 } else { alpha };
            renderer.draw_lines(&pts, [r, g, b, a], width)?;
        }
        drawn[kind as usize] += n;
    }
    // The curvature line families, each in its cue's style; with fading,
    // in the same four opacity bins of their strength.
    let fade = fx.lines.curves.fade;
    for st in &fx.lines.styles_for(&fx.cues) {
        let kind = st.family as u32;
        for (bi, &alpha) in BINS.iter().enumerate() {
            let pts: Vec<[f32; 3]> = lines
                .segments
                .iter()
                .filter(|s| s.2 == kind && (!fade || strength_bin(s.3) == bi))
                .flat_map(|s| [s.0, s.1])
                .collect();
            if pts.is_empty() || (!fade && bi > 0) {
                continue;
            }
            let [r, g, b] = st.color;
            let a = if fade { alpha } else { 1.0 };
            renderer.draw_lines(&pts, [r, g, b, a], st.width)?;
        }
    }
    if let Some(eo) = lines.edges {
        let [r, g, b] = fx.edge.1;
        draw_edges(renderer, eo, [r, g, b, 1.0])?;
    }
    if plan.contains(Pass::SdfLines) {
        // Strips over the surface (drawn first, so it hides the far side).
        let [r, g, b] = fx.strokes.color;
        let style = crate::render::strokes::StrokeStyle {
            color: [r, g, b, 1.0],
            width_scale: 1.0,
            lift: lines.stroke_lift,
        };
        crate::render::strokes::draw(renderer, cam, lines.strokes, &style)?;
    }
    // Depth only for an SVG's visibility test.
    let svg = paths
        .iter()
        .any(|p| p.extension().is_none_or(|e| e != "png"));
    let image: Frame = if svg {
        renderer.finish()?
    } else {
        renderer.finish_color()?
    };
    for path in paths {
        if path.extension().is_some_and(|e| e == "png") {
            image.save_png(path)?;
        } else {
            let layers = svg_layers(scene, plan, cam, &lines, &image);
            crate::export::svg::write_svg_layers(path, &layers, w, h)?;
        }
    }
    Ok((drawn, image))
}

/// The SVG groups of one view: one per line cue the scene asks for (contours,
/// suggestive contours, each curvature line family, feature edges), each with the cue's colour and width,
/// visible parts only (against `image`'s depth), joined into polylines.
fn svg_layers(
    scene: &Scene,
    plan: &Plan,
    cam: &Camera,
    lines: &ViewLines<'_>,
    image: &Frame,
) -> Vec<crate::export::svg::SvgLayer> {
    use crate::export::svg::{DEFAULT_BIAS, SvgLayer, SvgPolyline, segment_lines, visible_joined};
    use crate::spec::feature_lines::{Hidden, hidden_id};
    let fx = &scene.effects;
    let [w, h] = scene.size;
    let vp = cam.view_proj(w as f32 / h as f32);
    let mut layers = Vec::new();
    // Suggestive contours fade as in the image (four opacity bins).
    let alpha = |s: f32| [0.25, 0.5, 0.75, 1.0][strength_bin(s)];
    for (kind, id, (width, color)) in [
        (0u32, "contours", fx.contour),
        (1u32, "suggestive-contours", fx.suggestive),
    ] {
        let wanted = if kind == 0 {
            fx.cues.contains(&Cue::Contours)
        } else {
            fx.cues.contains(&Cue::SuggestiveContours)
        };
        if !wanted {
            continue;
        }
        let clip = segment_lines(vp, lines.segments, kind, |s| {
            if kind == 0 { 1.0 } else { alpha(s) }
        });
        layers.push(SvgLayer {
            id,
            stroke_width: width,
            color,
            lines: visible_joined(&clip, image, DEFAULT_BIAS),
            dashed: false,
        });
    }
    // The curvature line families as `shapecue lines` writes them: a group
    // per family, under it (as its `hidden` asks) the hidden parts.
    let fade = fx.lines.curves.fade;
    for st in &fx.lines.styles_for(&fx.cues) {
        let kind = st.family as u32;
        let clip = segment_lines(
            vp,
            lines.segments,
            kind,
            |s| {
                if fade { alpha(s) } else { 1.0 }
            },
        );
        if st.hidden != Hidden::Remove {
            let hidden: Vec<SvgPolyline> = lines
                .segments
                .iter()
                .filter(|s| s.2 == kind)
                .filter_map(|s| {
                    Some(SvgPolyline {
                        points: vec![pixel(vp, s.0, w, h)?, pixel(vp, s.1, w, h)?],
                        opacity: if st.hidden == Hidden::Faded { 0.3 } else { 1.0 },
                    })
                })
                .collect();
            layers.push(SvgLayer {
                id: hidden_id(st.family),
                stroke_width: 0.5 * st.width,
                color: st.color,
                lines: hidden,
                dashed: st.hidden == Hidden::Dashed,
            });
        }
        layers.push(SvgLayer {
            id: st.family.name(),
            stroke_width: st.width,
            color: st.color,
            lines: visible_joined(&clip, image, DEFAULT_BIAS),
            dashed: false,
        });
    }
    if let Some(eo) = lines.edges.filter(|_| plan.contains(Pass::Edges)) {
        let clip = crate::export::svg::edge_out_lines(&eo.edge_out);
        layers.push(SvgLayer {
            id: "feature-edges",
            stroke_width: fx.edge.0,
            color: fx.edge.1,
            lines: visible_joined(&clip, image, DEFAULT_BIAS),
            dashed: false,
        });
    }
    layers
}

/// `p` in image pixels (origin top left), or `None` behind the eye.
fn pixel(vp: glam::Mat4, p: [f32; 3], w: u32, h: u32) -> Option<[f32; 2]> {
    let c = vp * glam::Vec4::new(p[0], p[1], p[2], 1.0);
    if c.w.is_nan() || c.w <= 0.0 {
        return None;
    }
    let (x, y) = (c.x / c.w, c.y / c.w);
    Some([0.5 * (x + 1.0) * w as f32, 0.5 * (1.0 - y) * h as f32])
}
