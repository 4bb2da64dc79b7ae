//! Drawing and outputs: the scene's cameras resolved against the first
//! pose's bounds, the mesh colours and style, the line and edge quads, and
//! the PNG and SVG files of one view.

use super::interop::SharedEdges;
use super::vector::{LAYER_INTERSECTIONS, LAYER_STROKES, other_groups, stroke_segments};
pub(super) use super::vector::{line_styles, shown};
use crate::error::Result;
use crate::export::svg::{DEFAULT_BIAS, SvgLayer, SvgPolyline, segment_lines, visible_joined};
use crate::render::colormap::{curvature_color, with_ao};
use crate::render::edges::draw_edges;
use crate::render::{Camera, Frame, MeshStyle, Placement, Renderer, framed};
use crate::scene::file::{CameraKind, Effects, LineStyle, Scene, ViewSpec};
use crate::scene::planner::{Cue, Pass, Plan};
use crate::spec::edges::EdgeOutput;
use crate::spec::feature_lines::{Hidden, Segment, hidden_id};
use crate::spec::interop::{InteropDecision, InteropOffer};
use crate::spec::sdf_lines::{SdfLinesOutput, Stroke};
use crate::spec::timing::Timing;
use crate::spec::view::project_to_pixel as pixel;
use crate::stages::edges::SharedDrawn;
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

/// The opacity bin (0..4) of a faded segment's strength in (0, 1].
fn strength_bin(strength: f32) -> usize {
    ((strength.clamp(0.0, 1.0) * 4.0).ceil() as usize).clamp(1, 4) - 1
}

/// What one view draws on top of the mesh.
pub(super) struct ViewLines<'a> {
    /// Contour and suggestive-contour segments (scene frame).
    pub(super) segments: &'a [Segment],
    /// Intersection lines (scene frame).
    pub(super) intersections: &'a [Segment],
    /// The edge stage's outputs, when feature edges are planned.
    pub(super) edges: Option<&'a EdgeOutput>,
    /// On the external-memory route, the shared buffer and what the stage
    /// compacted into it (drawn from there instead of `edges`).
    pub(super) shared: Option<(&'a SharedEdges, &'a SharedDrawn)>,
    /// Curvature-directed strokes (scene frame).
    pub(super) strokes: &'a [Stroke],
    /// Lift of the strokes towards the eye (world units).
    pub(super) stroke_lift: f32,
}

/// Draws one view (the mesh the renderer holds, line quads, edge quads),
/// reads it back (with its depth when `depth`, for an SVG's hidden lines)
/// and writes it to the PNG `paths`.
pub(super) fn draw_view(
    renderer: &mut Renderer,
    scene: &Scene,
    plan: &Plan,
    cam: &Camera,
    lines: ViewLines<'_>,
    paths: &[&PathBuf],
    depth: bool,
) -> Result<Frame> {
    renderer.begin(cam)?;
    renderer.draw_uploaded(mesh_style(scene, plan))?;
    draw_line_families(renderer, &scene.effects, lines.segments)?;
    draw_edges_and_strokes(renderer, scene, plan, cam, &lines)?;
    let image: Frame = if depth {
        renderer.finish()?
    } else {
        renderer.finish_color()?
    };
    for path in paths {
        image.save_png(path)?;
    }
    Ok(image)
}

/// Whether an output path is a PNG.
pub(super) fn is_png(path: &std::path::Path) -> bool {
    has_ext(path, "png")
}

/// Whether an output path ends in `.ext`.
pub(super) fn has_ext(path: &std::path::Path, ext: &str) -> bool {
    path.extension().is_some_and(|e| e == ext)
}

/// The mesh's style: shaded, or flat in the background colour when only
/// lines are drawn.
fn mesh_style(scene: &Scene, plan: &Plan) -> MeshStyle {
    let fx = &scene.effects;
    let lines_only = !(plan.contains(Pass::Ao)
        || fx.cues.contains(&Cue::Shading)
        || fx.cues.contains(&Cue::CurvatureColors));
    if lines_only {
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
    }
}

/// Draws the line families' quads.
fn draw_line_families(renderer: &mut Renderer, fx: &Effects, segments: &[Segment]) -> Result<()> {
    // Faded families in four opacity bins of their strength.
    const BINS: [f32; 4] = [0.25, 0.5, 0.75, 1.0];
    for (st, faded) in line_styles(fx) {
        let kind = st.family as u32;
        for (bi, &alpha) in BINS.iter().enumerate() {
            if !faded && bi > 0 {
                break;
            }
            let pts: Vec<[f32; 3]> = segments
                .iter()
                .filter(|s| {
                    s.family == kind && shown(s) && (!faded || strength_bin(s.strength) == bi)
                })
                .flat_map(|s| [s.a, s.b])
                .collect();
            if pts.is_empty() {
                continue;
            }
            let [r, g, b] = st.color;
            let a = if faded { alpha } else { 1.0 };
            renderer.draw_lines(&pts, [r, g, b, a], st.width)?;
        }
    }
    Ok(())
}

/// Draws the feature edges (from the shared buffer or the read-back
/// outputs) and the curvature-directed strokes, where planned.
fn draw_edges_and_strokes(
    renderer: &mut Renderer,
    scene: &Scene,
    plan: &Plan,
    cam: &Camera,
    lines: &ViewLines<'_>,
) -> Result<()> {
    let fx = &scene.effects;
    if !lines.intersections.is_empty() {
        let pts: Vec<[f32; 3]> = (lines.intersections.iter())
            .flat_map(|s| [s.a, s.b])
            .collect();
        let [r, g, b] = fx.intersection.1;
        renderer.draw_lines(&pts, [r, g, b, 1.0], fx.intersection.0)?;
    }
    if let Some(eo) = lines.edges {
        let [r, g, b] = fx.edge.1;
        match lines.shared {
            Some((sh, d)) => sh.draw(renderer, d, [r, g, b, 1.0])?,
            None => draw_edges(renderer, eo, [r, g, b, 1.0])?,
        }
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
    Ok(())
}

/// The SVG groups of one view: for each line family the scene draws
/// ([`line_styles`]) its visible parts (against `image`'s depth), and under
/// them, as the family's `hidden` asks, its hidden parts; then the strokes,
/// intersection lines and feature edges ([`other_groups`]). The SVG layer
/// writer of the depth-buffer method ([`super::vector::svg_layers_exact`]
/// is the exact method's).
pub(super) fn svg_layers(
    scene: &Scene,
    cam: &Camera,
    lines: &ViewLines<'_>,
    image: &Frame,
) -> Vec<SvgLayer> {
    let fx = &scene.effects;
    let vp = cam.view_proj(scene.size[0] as f32 / scene.size[1] as f32);
    let mut layers = Vec::new();
    for (st, faded) in line_styles(fx) {
        family_layers(&mut layers, &st, faded, lines.segments, vp, image);
    }
    let view = cam.view(scene.size[0], scene.size[1]);
    for (cue, id, (stroke_width, color), layer) in other_groups(fx) {
        if !fx.cues.contains(&cue) {
            continue;
        }
        let clip = match (layer, lines.edges) {
            (LAYER_STROKES, _) => {
                let segs = stroke_segments(lines.strokes, &view, lines.stroke_lift);
                segment_lines(vp, &segs, layer, |_| 1.0)
            }
            (LAYER_INTERSECTIONS, _) => segment_lines(vp, lines.intersections, layer, |_| 1.0),
            (_, Some(eo)) => crate::export::svg::edge_out_lines(&eo.edge_out),
            (_, None) => continue,
        };
        layers.push(SvgLayer {
            id,
            stroke_width,
            color,
            lines: visible_joined(&clip, image, DEFAULT_BIAS),
            dashed: false,
        });
    }
    layers
}

/// One line family's SVG groups: the hidden parts (as its style asks) under
/// the visible ones, joined into polylines; a faded family's opacity is its
/// strength.
fn family_layers(
    layers: &mut Vec<SvgLayer>,
    st: &LineStyle,
    faded: bool,
    segments: &[Segment],
    vp: glam::Mat4,
    image: &Frame,
) {
    let kind = st.family as u32;
    let (w, h) = (image.width, image.height);
    let ours: Vec<Segment> = (segments.iter())
        .filter(|s| s.family == kind && shown(s))
        .copied()
        .collect();
    if st.hidden != Hidden::Remove {
        // Every segment projected, under the visible group: where the
        // visible group does not cover it, the line is hidden.
        let opacity = if st.hidden == Hidden::Faded { 0.3 } else { 1.0 };
        let hidden = (ours.iter())
            .filter_map(|s| {
                Some(SvgPolyline {
                    points: vec![pixel(vp, s.a, w, h)?, pixel(vp, s.b, w, h)?],
                    opacity,
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
    let clip = segment_lines(
        vp,
        &ours,
        kind,
        |s| {
            if faded { s.clamp(0.0, 1.0) } else { 1.0 }
        },
    );
    layers.push(SvgLayer {
        id: st.family.name(),
        stroke_width: st.width,
        color: st.color,
        lines: visible_joined(&clip, image, DEFAULT_BIAS),
        dashed: false,
    });
}

/// What a view drawn into memory hands its caller.
pub struct ViewOutputs {
    /// The image (RGBA, row 0 at the top), where the plan drew one (a PNG,
    /// or the depth-buffer method's hidden lines).
    pub image: Option<Frame>,
    /// The SVG groups (the scene's `svg` output asked for them).
    pub layers: Option<Vec<SvgLayer>>,
    /// The lines classified and chained by exact visibility (world
    /// coordinates), where the plan ran it.
    pub visible: Option<super::vector::VisibleLines>,
    /// The per-vertex fields of the view (world units), where the scene
    /// keeps them ([`crate::scene::file::Scene::fields`]).
    pub fields: Option<crate::spec::feature_lines::ViewFields>,
    /// The pieces as NPZ arrays, with the pose they lie on, where the scene
    /// writes NPZ.
    pub npz: Option<PosedPieces>,
    /// The line segments found for this view (world coordinates).
    pub segments: Vec<Segment>,
    /// The edge stage's outputs as drawn, when feature edges are planned.
    pub edges: Option<EdgeOutput>,
    /// The curvature-directed strokes run of the pose: seeds, strokes
    /// (world coordinates), counts and parameters.
    pub strokes: SdfLinesOutput,
    /// The camera, in the scene frame (world minus `origin`, so that f32
    /// keeps its precision far from the world origin).
    pub camera: Camera,
    /// World position of the scene frame's origin (the centre of the first
    /// pose's bounds).
    pub origin: [f64; 3],
    /// The topology's mesh (world coordinates), for a picture: the surface
    /// drawn for a static mesh or an isosurface; the rest pose (skinned) or
    /// the first frame (flipbook) of an animation.
    pub mesh: Option<crate::mesh::Mesh>,
    /// The feature edges' buffer counts and route, when they are planned.
    pub edge_info: Option<EdgeInfo>,
    /// Mesh data uploads to GL so far.
    pub uploads: crate::render::Uploads,
    /// The feature size the line families' thresholds were scaled by, when
    /// lines were found.
    pub feature_size: Option<f32>,
    /// Kernel time of this pose's curvature run and this view's lines and
    /// edges.
    pub timing: Timing,
}

/// A view's pieces as NPZ arrays (world coordinates, with the face and
/// barycentric coordinates each lies at) and the pose's vertex positions
/// (world) those coordinates refer to.
#[derive(Clone, Debug, Default)]
pub struct PosedPieces {
    /// The pieces.
    pub arrays: crate::export::npz::SegmentArrays,
    /// The pose's vertex positions.
    pub positions: Vec<[f64; 3]>,
}

impl ViewOutputs {
    /// The camera in world coordinates.
    pub fn world_camera(&self) -> Camera {
        let shift = glam::DVec3::from(self.origin).as_vec3();
        Camera {
            eye: self.camera.eye + shift,
            target: self.camera.target + shift,
            ..self.camera
        }
    }
}

/// What a run hands its caller after each view
/// ([`Session::run_each`](super::Session::run_each),
/// [`Session::run_in_memory`](super::Session::run_in_memory)), before the
/// next view starts: what was found and drawn for it, in world
/// coordinates, the passes that ran for it, and the files it wrote.
pub struct ViewDone {
    /// The frame (its index in the input's frames).
    pub frame: usize,
    /// The view (its index in the scene's views).
    pub view: usize,
    /// What the view found and drew: its lines (and, with exact
    /// visibility, their pieces and chains), the fields where the scene
    /// keeps them, and in memory the image and SVG groups its scene asks
    /// for.
    pub out: ViewOutputs,
    /// The passes that ran for this view (the pose's too, where they ran
    /// for it), in plan order, with their ms.
    pub passes: Vec<super::report::PassRecord>,
    /// The images the view wrote (PNG, SVG); none in memory.
    pub files: Vec<PathBuf>,
}

/// The edge buffer's counts (House & Li's edge buffer and the adjacency
/// caps' pairs).
#[derive(Clone, Copy, Debug, Default, PartialEq, serde::Serialize)]
pub struct EdgeCounts {
    /// Unique edges.
    pub edges: usize,
    /// Adjacency cap pairs (0 without adjacency caps).
    pub cap_pairs: usize,
    /// Boundary edges (one face).
    pub boundary: usize,
    /// Non-manifold edges (three faces or more).
    pub non_manifold: usize,
    /// Marked edges.
    pub marked: usize,
}

/// What a view with feature edges hands its caller besides their outputs.
#[derive(Clone, Debug)]
pub struct EdgeInfo {
    /// The edge buffer's counts.
    pub counts: EdgeCounts,
    /// The route the buffers took to GL, and why.
    pub decision: InteropDecision,
    /// What the device, GL and Vulkan offered.
    pub offer: InteropOffer,
    /// Adjacency caps drawn.
    pub drawn_caps: usize,
}
