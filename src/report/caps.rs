//! `shapecue report caps`: cap quality of the edges stage (House & Li's
//! table), how closely each cap variant's rendered stroke matches the ideal
//! round-joined stroke of the same edges, on the standard meshes.
//!
//! It measures a *drawing*: it runs the stage, rasterises the edges and caps
//! with the GL renderer and compares the covered pixels with an analytic
//! coverage ([`ideal_coverage`]). Compute knows no screen and the screen
//! runs no compute; the measurement, above both, composes them.

use std::sync::Arc;

use serde::Serialize;

use super::{Block, Cell, Chart, Column, Report, Row, Table, edge_meshes};
use crate::error::Result;
use crate::gpu::Gpu;
use crate::mesh::Mesh;
use crate::mesh::edges::EdgeTopology;
use crate::render::edges::draw_edges;
use crate::render::{Placement, RenderOptions, Renderer, framed};
use crate::spec::edges::{CapMode, EdgeParams, crease_from_degrees};
use crate::stages::edges::EdgeStage;

/// The view and strokes of the report (the `edges` command's options of
/// the same names).
#[derive(Clone, Copy, Debug)]
pub struct CapsReportOptions {
    /// Image size in pixels.
    pub size: (u32, u32),
    /// Edge width in pixels.
    pub width: f32,
    /// Crease angle in degrees.
    pub crease_deg: f32,
    /// Vertical field of view in degrees.
    pub fov_deg: f32,
    /// Orthographic projection.
    pub ortho: bool,
}

impl Default for CapsReportOptions {
    fn default() -> Self {
        CapsReportOptions {
            size: (800, 600),
            width: 4.0,
            crease_deg: 30.0,
            fov_deg: 40.0,
            ortho: false,
        }
    }
}

/// The report: gap and extra pixels of each cap variant against the ideal
/// round-joined stroke ([`cap_quality`]), unit-sized meshes seen from
/// (5, 5, 5).
///
/// # Errors
/// Bad width or crease, device and GL failures.
pub fn report(gpu: &Arc<Gpu>, o: CapsReportOptions) -> Result<Report> {
    let (w, h) = o.size;
    let crease = crease_from_degrees(o.crease_deg)?;
    let mut r = Report::new("caps", gpu.info.name.clone());
    r.text(format!(
        "eye (5,5,5), unit-sized meshes at the origin, {w}x{h}, width {} px, crease {}°",
        o.width, o.crease_deg
    ));
    let mut t = Table::new(
        "caps",
        vec![
            Column::new("mesh", "mesh"),
            Column::new("caps", "caps"),
            Column::new("ideal", "ideal_px"),
            Column::new("rendered", "rendered_px"),
            Column::new("gap", "gap_px"),
            Column::new("extra", "extra_px"),
        ],
    );
    let mut groups = Vec::new();
    let mut series: Vec<(String, Vec<f64>)> = CapMode::ALL
        .iter()
        .map(|m| (m.name().to_string(), Vec::new()))
        .collect();
    for (name, m) in edge_meshes() {
        let topo = EdgeTopology::new(&m, &[], &name)?;
        let cam = framed(
            Placement::At(glam::Vec3::splat(5.0)),
            Some(glam::Vec3::ZERO),
            None,
            o.fov_deg,
            o.ortho,
            m.bounds(),
            w as f32 / h as f32,
        )?;
        let mut p = EdgeParams::new(cam.view(w, h));
        p.line_width = o.width;
        p.crease_deg = crease;
        for q in cap_quality(gpu.clone(), &m, &topo, &p)? {
            if let Some(s) = series.iter_mut().find(|s| s.0 == q.mode.name()) {
                s.1.push(q.gap as f64);
            }
            t.rows.push(Row::new(vec![
                Cell::text(name.clone()),
                Cell::text(q.mode.name()),
                Cell::int(q.ideal),
                Cell::int(q.rendered),
                Cell::int(q.gap),
                Cell::int(q.extra),
            ]));
        }
        groups.push(name);
    }
    r.blocks.push(Block::Table(t));
    r.charts.push(Chart::Bars {
        title: "Cap quality: gap pixels against the ideal round-joined stroke".into(),
        y_label: "gap pixels".into(),
        log_y: false,
        groups,
        series,
    });
    Ok(r)
}

/// How closely one cap variant's stroke matches the ideal round-joined stroke.
#[derive(Clone, Debug, Serialize)]
pub struct CapQuality {
    /// The cap variant.
    pub mode: CapMode,
    /// Pixels of the ideal stroke.
    pub ideal: usize,
    /// Pixels the renderer covered (edges and caps, no mesh, no MSAA).
    pub rendered: usize,
    /// Ideal covered, rendered not.
    pub gap: usize,
    /// Rendered, ideal not.
    pub extra: usize,
}

/// The ideal stroke of the drawn edges of `edge_out`: pixels whose centre is
/// within `half_width` pixels of a projected edge (the union of discs along
/// every edge), `width × height`, row 0 at the top.
pub fn ideal_coverage(
    edge_out: &[[f32; 4]],
    width: u32,
    height: u32,
    half_width: f32,
) -> Vec<bool> {
    let (w, h) = (width as usize, height as usize);
    let mut cov = vec![false; w * h];
    // The midpoint of a and b in clip space, over a's w (the edge's end).
    let px = |a: [f32; 4], b: [f32; 4]| {
        let mid = [0.5 * (a[0] + b[0]), 0.5 * (a[1] + b[1]), 0.0, a[3]];
        let [x, y, _] = crate::spec::view::clip_to_pixel(mid, width, height);
        [x, y]
    };
    for q in edge_out.chunks_exact(4) {
        if q[0][0].is_nan() || !q.iter().flatten().all(|c| c.is_finite()) {
            continue;
        }
        let (a, b) = (px(q[0], q[3]), px(q[1], q[2]));
        let r = half_width;
        let x0 = (a[0].min(b[0]) - r).floor().max(0.0) as usize;
        let x1 = ((a[0].max(b[0]) + r).ceil().max(0.0) as usize).min(w);
        let y0 = (a[1].min(b[1]) - r).floor().max(0.0) as usize;
        let y1 = ((a[1].max(b[1]) + r).ceil().max(0.0) as usize).min(h);
        let d = [b[0] - a[0], b[1] - a[1]];
        let dd = d[0] * d[0] + d[1] * d[1];
        for y in y0..y1 {
            for x in x0..x1 {
                let p = [x as f32 + 0.5 - a[0], y as f32 + 0.5 - a[1]];
                let t = if dd > 0.0 {
                    ((p[0] * d[0] + p[1] * d[1]) / dd).clamp(0.0, 1.0)
                } else {
                    0.0
                };
                let (ex, ey) = (p[0] - t * d[0], p[1] - t * d[1]);
                if ex * ex + ey * ey <= r * r {
                    cov[y * w + x] = true;
                }
            }
        }
    }
    cov
}

/// Cap quality of every variant for one mesh and view: runs the stage,
/// renders only the edges and caps (black on white, no MSAA, at the view's
/// viewport) and compares the covered pixels with [`ideal_coverage`]
/// (constant width: `depth_scale` is ignored).
pub fn cap_quality(
    gpu: Arc<Gpu>,
    mesh: &Mesh,
    topo: &EdgeTopology,
    params: &EdgeParams,
) -> Result<Vec<CapQuality>> {
    let mut p = *params;
    p.depth_scale = None;
    let (w, h) = (p.view.width, p.view.height);
    let mut stage = EdgeStage::new(gpu, mesh, topo)?;
    let mut r = Renderer::new(RenderOptions {
        width: w,
        height: h,
        msaa: 0,
        background: [1.0; 4],
    })?;
    let mut rows = Vec::new();
    for mode in CapMode::ALL {
        stage.run(&p, mode)?;
        let out = stage.read()?;
        r.begin_view(&p.view)?;
        draw_edges(&mut r, &out, [0.0, 0.0, 0.0, 1.0])?;
        let frame = r.finish()?;
        let ideal = ideal_coverage(&out.edge_out, w, h, 0.5 * p.line_width);
        let mut q = CapQuality {
            mode,
            ideal: 0,
            rendered: 0,
            gap: 0,
            extra: 0,
        };
        for (i, &want) in ideal.iter().enumerate() {
            let got = frame.rgba[4 * i] < 128;
            q.ideal += want as usize;
            q.rendered += got as usize;
            q.gap += (want && !got) as usize;
            q.extra += (got && !want) as usize;
        }
        rows.push(q);
    }
    Ok(rows)
}
