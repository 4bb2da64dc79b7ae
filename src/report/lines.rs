//! The line families of each curvature solve against analytic lines (a
//! table of `shapecue report curvature`): the exact least squares (the
//! default) and trimesh2's (what rtsc computes, `--compat trimesh2`), on
//! shapes whose lines are known in closed form, beside the kernel time.

use super::{Block, Cell, Column, Report, Row, Table};
use crate::api::{LineSetup, line_segments_on};
use crate::error::Result;
use crate::gpu::Gpu;
use crate::mesh::{self, Mesh};
use crate::spec::curvature::{Compat, CurvatureOptions};
use crate::spec::feature_lines::{CurveOptions, FamilySet, FeatureSize, LineFamily, Segment};
use crate::spec::view::View;
use crate::stages::feature_lines::LineOptions;
use std::sync::Arc;

/// The analytic errors of one solve's lines.
#[derive(Clone, Copy, Debug)]
pub struct LineErrors {
    /// Mean distance of the torus's K = 0 segment ends from its top and
    /// bottom circles (ρ = R, z = ±r), R = 1, r = 0.4.
    pub torus_k_zero: f64,
    /// Mean distance of the ellipsoid's ridge segment midpoints from the
    /// nearest of its principal planes (semi-axes 1.5, 1, 0.6).
    pub ellipsoid_ridges: f64,
    /// Kernel ms of both extractions (curvature and lines).
    pub kernel_ms: f64,
}

fn segments(
    gpu: &Arc<Gpu>,
    m: &Mesh,
    view: View,
    family: LineFamily,
    compat: Compat,
) -> Result<(Vec<Segment>, f64)> {
    let opts = LineOptions {
        contours: false,
        suggestive: false,
        curves: CurveOptions {
            families: FamilySet::of(&[family]),
            ridge_threshold: 0.0,
            cull: false,
            ..Default::default()
        },
        ..Default::default()
    };
    let setup = LineSetup {
        curvature: CurvatureOptions {
            compat,
            ..Default::default()
        },
        feature_size: FeatureSize::Edge,
    };
    let ls = line_segments_on(gpu, m, view, &opts, &setup)?;
    Ok((ls.segments, ls.timing.kernel_ms))
}

/// The lines of one solve against the analytic ones.
pub fn analytic_errors(gpu: &Arc<Gpu>, compat: Compat) -> Result<LineErrors> {
    let torus = mesh::torus(1.0, 0.4, 90, 36);
    let view = View::from_eye([0.0, 0.0, 4.0], false);
    let (s, t1) = segments(gpu, &torus, view, LineFamily::KZero, compat)?;
    let ends: Vec<[f32; 3]> = s.iter().flat_map(|s| [s.a, s.b]).collect();
    let torus_k_zero = ends
        .iter()
        .map(|p| {
            let rho = f64::from(p[0]).hypot(f64::from(p[1]));
            ((rho - 1.0).powi(2) + (f64::from(p[2]).abs() - 0.4).powi(2)).sqrt()
        })
        .sum::<f64>()
        / ends.len().max(1) as f64;
    let ellipsoid = mesh::uv_ellipsoid(1.5, 1.0, 0.6, 160, 80);
    let view = View::from_eye([0.0, 0.0, 1.0], true);
    let (s, t2) = segments(gpu, &ellipsoid, view, LineFamily::Ridges, compat)?;
    let ellipsoid_ridges = s
        .iter()
        .map(|s| {
            (0..3)
                .map(|i| (0.5 * (f64::from(s.a[i]) + f64::from(s.b[i]))).abs())
                .fold(f64::INFINITY, f64::min)
        })
        .sum::<f64>()
        / s.len().max(1) as f64;
    Ok(LineErrors {
        torus_k_zero,
        ellipsoid_ridges,
        kernel_ms: t1 + t2,
    })
}

/// Appends the table of both solves to `r`.
pub fn table(gpu: &Arc<Gpu>, r: &mut Report) -> Result<()> {
    r.text(
        "\nLine families of each solve against analytic lines: mean distance of a torus's \
         K = 0 lines (R=1 r=0.4, 3,240 vertices) from its top and bottom circles, and of a \
         triaxial ellipsoid's ridges (1.5, 1, 0.6; 12,642 vertices) from its principal planes; \
         kernel ms of curvature and lines, both shapes",
    );
    let mut t = Table::new(
        "lines",
        vec![
            Column::new("curvature solve", "solve"),
            Column::new("torus K = 0 error", "torus_k_zero_error"),
            Column::new("ellipsoid ridge error", "ellipsoid_ridge_error"),
            Column::new("kernel ms", "kernel_ms"),
        ],
    );
    for (name, compat) in [
        ("exact (default)", Compat::Exact),
        ("trimesh2 (rtsc's, --compat trimesh2)", Compat::Trimesh2),
    ] {
        let e = analytic_errors(gpu, compat)?;
        t.rows.push(Row::new(vec![
            Cell::text(name),
            Cell::sci(e.torus_k_zero, 2),
            Cell::sci(e.ellipsoid_ridges, 2),
            Cell::num(e.kernel_ms, format!("{:.2}", e.kernel_ms)),
        ]));
    }
    r.blocks.push(Block::Table(t));
    Ok(())
}
