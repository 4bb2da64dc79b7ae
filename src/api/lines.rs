//! [`lines_picture`]: every line family of rtsc (occluding and suggestive
//! contours, ridges, valleys, apparent ridges, highlights, isophotes,
//! K = 0, H = 0, D_w κr = 0, boundaries) of one mesh seen from one camera:
//! curvature with its derivative, the feature-line stage, and a picture of
//! the lines over the mesh drawn flat in white (the mesh hides what is
//! behind it), with the SVG groups of the visible (and, as asked, the
//! hidden) parts per family.

use crate::error::Result;
use crate::export::svg::{DEFAULT_BIAS, SvgLayer, SvgPolyline, segment_lines, visible_joined};
use crate::gpu::Gpu;
use crate::mesh::Mesh;
use crate::render::{Camera, Frame, Placement, framed};
use crate::render::{MeshStyle, RenderOptions, Renderer};
use crate::spec::curvature::CurvatureOptions;
use crate::spec::feature_lines::{FeatureSize, LineFamily, LineInputs, Segment};
pub use crate::spec::feature_lines::{Hidden, family_style, hidden_id};
use crate::spec::timing::Timing;
use crate::spec::view::View;
use crate::stages::curvature::estimate;
use crate::stages::feature_lines::{LineExtractor, LineOptions};
use glam::Vec3;
use std::sync::Arc;

/// What [`lines_picture`] draws and how (the `shapecue lines` options).
#[derive(Clone, Debug, PartialEq)]
pub struct LinesPictureOptions {
    /// Eye position; `None`: framed from direction (1, 1, 1).
    pub eye: Option<Vec3>,
    /// Point looked at; `None`: the centre of the bounding box.
    pub target: Option<Vec3>,
    /// Up direction; `None`: +Y, or +Z when looking along Y.
    pub up: Option<Vec3>,
    /// Vertical field of view in degrees.
    pub fov_deg: f32,
    /// Orthographic projection.
    pub ortho: bool,
    /// Image width in pixels.
    pub width: u32,
    /// Image height in pixels.
    pub height: u32,
    /// The families and their controls.
    pub lines: LineOptions,
    /// Line width in pixels.
    pub line_width: f32,
    /// Hidden parts in the SVG.
    pub hidden: Hidden,
    /// Also find the SVG groups.
    pub svg: bool,
    /// The curvature and the feature size the lines are found with.
    pub setup: LineSetup,
}

/// What the line families are computed from besides the view: the
/// curvature estimator's options (the derivative is always on) and the
/// feature size the thresholds are scaled by.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct LineSetup {
    /// Scheme, precision and least squares of the curvature (default:
    /// gather, f32, the exact solve; `Compat::Trimesh2` gives rtsc's own).
    pub curvature: CurvatureOptions,
    /// The thresholds' scale (default: rtsc's).
    pub feature_size: FeatureSize,
}

impl Default for LinesPictureOptions {
    fn default() -> Self {
        LinesPictureOptions {
            eye: None,
            target: None,
            up: None,
            fov_deg: 40.0,
            ortho: false,
            width: 800,
            height: 600,
            lines: LineOptions::default(),
            line_width: 2.0,
            hidden: Hidden::Remove,
            svg: false,
            setup: LineSetup::default(),
        }
    }
}

/// The result of [`lines_picture`].
pub struct LinesPicture {
    /// The picture (lines over the mesh in white).
    pub frame: Frame,
    /// Every segment, world coordinates, with its family (`kind`) and strength.
    pub segments: Vec<Segment>,
    /// The SVG groups, one per family (and one per family's hidden parts).
    pub layers: Option<Vec<SvgLayer>>,
    /// Kernel ms of curvature and line steps.
    pub timing: Timing,
    /// The camera.
    pub camera: Camera,
    /// The feature size the thresholds were scaled by.
    pub feature_size: f32,
}

/// [`lines_picture_on`] on the default device.
pub fn lines_picture(mesh: &Mesh, opts: &LinesPictureOptions) -> Result<LinesPicture> {
    lines_picture_on(&super::default_gpu()?, mesh, opts)
}

/// Every requested line family of `mesh` from the options' camera.
pub fn lines_picture_on(
    gpu: &Arc<Gpu>,
    mesh: &Mesh,
    opts: &LinesPictureOptions,
) -> Result<LinesPicture> {
    let (w, h) = (opts.width, opts.height);
    let bounds = mesh.bounds();
    let placement = match opts.eye {
        Some(e) => Placement::At(e),
        None => Placement::Fit(Vec3::ONE),
    };
    let cam = framed(
        placement,
        opts.target,
        opts.up,
        opts.fov_deg,
        opts.ortho,
        bounds,
        w as f32 / h as f32,
    )?;
    let ls = line_segments_on(gpu, mesh, cam.view(w, h), &opts.lines, &opts.setup)?;
    let (segments, timing, fs) = (ls.segments, ls.timing, ls.feature_size);
    let pos: Vec<[f32; 3]> = mesh.positions.iter().map(|p| p.map(|c| c as f32)).collect();
    let nrm = crate::mesh::topology::vertex_normals(mesh);
    let families = wanted(&opts.lines);
    let mut r = Renderer::new(RenderOptions {
        width: w,
        height: h,
        ..Default::default()
    })?;
    r.upload_topology(&mesh.faces)?;
    r.upload_pose(&pos, &nrm, &[])?;
    r.begin(&cam)?;
    r.draw_uploaded(MeshStyle {
        ambient: 1.0,
        color: [1.0, 1.0, 1.0],
        ..MeshStyle::default()
    })?;
    for &fam in &families {
        let pts: Vec<[f32; 3]> = segments
            .iter()
            .filter(|s| s.2 == fam as u32 && s.3 > 0.0)
            .flat_map(|s| [s.0, s.1])
            .collect();
        if pts.is_empty() {
            continue;
        }
        let ([cr, cg, cb], wf) = family_style(fam);
        r.draw_lines(&pts, [cr, cg, cb, 1.0], opts.line_width * wf)?;
    }
    let frame = if opts.svg {
        r.finish()?
    } else {
        r.finish_color()?
    };
    let layers = opts
        .svg
        .then(|| svg_layers(&cam, &segments, &families, &frame, opts));
    Ok(LinesPicture {
        frame,
        segments,
        layers,
        timing,
        camera: cam,
        feature_size: fs,
    })
}

/// The segments of [`line_segments_on`].
pub struct LineSegments {
    /// Every segment, world coordinates, with its family (`kind`) and strength.
    pub segments: Vec<Segment>,
    /// Kernel ms of curvature and line steps.
    pub timing: Timing,
    /// The feature size the thresholds were scaled by.
    pub feature_size: f32,
}

/// The line segments of `mesh` seen from `view` (no picture, no GL):
/// curvature with its derivative (on the device, as `setup` asks), then
/// every family `opts` asks for, thresholds scaled by `setup`'s feature
/// size.
pub fn line_segments_on(
    gpu: &Arc<Gpu>,
    mesh: &Mesh,
    view: View,
    opts: &LineOptions,
    setup: &LineSetup,
) -> Result<LineSegments> {
    let copts = CurvatureOptions {
        dcurv: true,
        ..setup.curvature
    };
    let run = estimate(gpu.clone(), mesh, copts)?;
    let f = &run.field;
    let c3 = |v: &[[f64; 3]]| -> Vec<[f32; 3]> { v.iter().map(|p| p.map(|c| c as f32)).collect() };
    let pos = c3(&mesh.positions);
    let (nrm, d1, d2) = (c3(&f.normals), c3(&f.d1), c3(&f.d2));
    let k: Vec<[f32; 2]> =
        f.k1.iter()
            .zip(&f.k2)
            .map(|(a, b)| [*a as f32, *b as f32])
            .collect();
    let dk: Vec<[f32; 4]> = f.dk.iter().map(|d| d.map(|c| c as f32)).collect();
    let x = LineInputs {
        pos: &pos,
        nrm: &nrm,
        d1: &d1,
        d2: &d2,
        k: &k,
        dk: &dk,
    };
    let fs = crate::mesh::feature_size::resolve(
        setup.feature_size,
        &mesh.positions,
        &mesh.faces,
        Some(&|i| [f.k1[i], f.k2[i]]),
    ) as f32;
    let mut ex = LineExtractor::new(gpu.clone(), mesh.n_vertices(), &mesh.faces)?;
    let (segments, st) = ex.extract(&x, view, fs, *opts)?;
    let mut timing = run.timing.clone();
    timing.extend(&st.timing);
    Ok(LineSegments {
        segments,
        timing,
        feature_size: fs,
    })
}

/// The families the options ask for, by index.
pub fn wanted(o: &LineOptions) -> Vec<LineFamily> {
    let mut v = Vec::new();
    if o.contours {
        v.push(LineFamily::Contours);
    }
    if o.suggestive {
        v.push(LineFamily::Suggestive);
    }
    v.extend(o.curves.families.curves().iter());
    v
}

fn svg_layers(
    cam: &Camera,
    segments: &[Segment],
    families: &[LineFamily],
    frame: &Frame,
    opts: &LinesPictureOptions,
) -> Vec<SvgLayer> {
    let (w, h) = (opts.width, opts.height);
    let vp = cam.view_proj(w as f32 / h as f32);
    let mut layers = Vec::new();
    for &fam in families {
        let (color, wf) = family_style(fam);
        let width = opts.line_width * wf;
        let clip = segment_lines(vp, segments, fam as u32, |s| s.clamp(0.0, 1.0));
        if opts.hidden != Hidden::Remove {
            // Every segment projected, under the visible group: where the
            // visible group does not cover it, the line is hidden.
            let lines: Vec<SvgPolyline> = segments
                .iter()
                .filter(|s| s.2 == fam as u32)
                .filter_map(|s| {
                    let a = pixel(vp, s.0, w, h)?;
                    let b = pixel(vp, s.1, w, h)?;
                    Some(SvgPolyline {
                        points: vec![a, b],
                        opacity: if opts.hidden == Hidden::Faded {
                            0.3
                        } else {
                            1.0
                        },
                    })
                })
                .collect();
            layers.push(SvgLayer {
                id: hidden_id(fam),
                stroke_width: 0.5 * width,
                color,
                lines,
                dashed: opts.hidden == Hidden::Dashed,
            });
        }
        layers.push(SvgLayer {
            id: fam.name(),
            stroke_width: width,
            color,
            lines: visible_joined(&clip, frame, DEFAULT_BIAS),
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
