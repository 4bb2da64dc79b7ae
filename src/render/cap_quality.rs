//! Cap-quality evaluation of the edges stage (House & Li's table): how closely
//! each cap variant's rendered stroke matches the ideal round-joined stroke
//! of the same edges.
//!
//! It lives beside the renderer, not in `stages/`, because it measures a
//! *drawing*: it runs the stage, rasterises the edges and caps with the GL
//! renderer and compares the covered pixels with an analytic coverage
//! ([`ideal_coverage`]). Compute knows no screen; this is where the screen
//! judges the compute.

use std::sync::Arc;

use serde::Serialize;

use super::edges::draw_edges;
use super::{RenderOptions, Renderer};
use crate::error::Result;
use crate::gpu::Gpu;
use crate::mesh::Mesh;
use crate::mesh::edges::EdgeTopology;
use crate::spec::edges::{CapMode, EdgeParams};
use crate::stages::edges::EdgeStage;

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
    let px = |a: [f32; 4], b: [f32; 4]| {
        let (x, y, cw) = (0.5 * (a[0] + b[0]), 0.5 * (a[1] + b[1]), a[3]);
        [
            (x / cw * 0.5 + 0.5) * w as f32,
            (0.5 - y / cw * 0.5) * h as f32,
        ]
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
