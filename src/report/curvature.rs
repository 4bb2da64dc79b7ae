//! `shapecue report curvature`: every curvature variant on a torus of about
//! `resolution` vertices (error against the analytic curvature, error
//! against the f64 CPU reference, median kernel and wall time), then a
//! refinement sweep showing how the analytic error falls with resolution
//! for the exact solve and stalls for the trimesh2-compatible one.

use super::metrics::{analytic_rms, label, measure, nrmse, torus_truth, variants};
use super::{Block, Cell, Chart, Column, Report, Row, Table};
use crate::error::{Error, Result};
use crate::gpu::Gpu;
use crate::mesh;
use crate::spec::curvature::{Compat, CurvatureOptions, Precision};
use std::sync::Arc;
use std::time::Instant;

/// The report's sizes: torus vertices and runs per variant (medians).
#[derive(Clone, Copy, Debug)]
pub struct CurvatureReportOptions {
    /// Approximate vertex count of the torus of the variants table.
    pub resolution: usize,
    /// Timed runs per variant (the refinement sweep uses at most 3).
    pub runs: usize,
}

impl Default for CurvatureReportOptions {
    fn default() -> Self {
        CurvatureReportOptions {
            resolution: 40_000,
            runs: 7,
        }
    }
}

/// The vertex counts of the refinement sweep.
pub const REFINEMENT: [usize; 4] = [2_500, 10_000, 40_000, 160_000];

fn e3(v: f64) -> Cell {
    Cell::sci(v, 3)
}

fn ms(v: f64) -> Cell {
    Cell::num(v, format!("{v:.2}"))
}

/// A scatter chart's (label, x, y) points.
type Points = Vec<(String, f64, f64)>;

/// A convergence chart's series: (name, (h, error) points).
type Series = Vec<(String, Vec<(f64, f64)>)>;

/// Measures the report on `gpu`.
///
/// # Errors
/// Device failures other than a variant the device cannot run (that one is
/// a row saying why).
pub fn report(gpu: &Arc<Gpu>, o: CurvatureReportOptions) -> Result<Report> {
    let runs = o.runs;
    let mut r = Report::new("curvature", gpu.info.name.clone());
    let (nu, nv) = mesh::torus_resolution_for(o.resolution);
    let m = mesh::torus(1.0, 0.4, nu, nv);
    r.text(format!(
        "Curvature variants on a torus R=1 r=0.4, {} vertices, {} faces; device: {} ({} CUs)\n\
         errors: RMS of k1, k2 against the analytic torus; NRMSE of H = (k1+k2)/2 against the f64 \
         CPU reference of the same solve; times: median of {runs} runs, all passes incl. dcurv \
         unless noted, mesh on the device",
        m.n_vertices(),
        m.n_faces(),
        gpu.info.name,
        gpu.info.compute_units
    ));
    let (t, points) = variants_table(gpu, &m, runs)?;
    r.blocks.push(Block::Table(t));
    r.charts.push(Chart::Scatter {
        title: format!(
            "Curvature variants, torus of {} vertices: k1 error against kernel time",
            m.n_vertices()
        ),
        x_label: "median kernel ms".into(),
        y_label: "k1 RMS error vs analytic".into(),
        points,
    });

    r.text(
        "\nRefinement: RMS error of k1 against the analytic torus (exact solve converges ~h², \
         trimesh2's pivot quirk does not)",
    );
    let (t, series) = refinement_table(gpu, runs)?;
    r.blocks.push(Block::Table(t));
    r.charts.push(Chart::Convergence {
        title: "Refinement: k1 error against edge length h (torus)".into(),
        x_label: "h (tube circumference / segments)".into(),
        y_label: "k1 RMS error vs analytic".into(),
        series,
    });
    super::lines::table(gpu, &mut r)?;
    Ok(r)
}

/// Every variant on the torus `m` (a row saying why for one the device
/// cannot run), then the CPU reference; with the (label, kernel ms, k1
/// error) points of the scatter chart.
fn variants_table(gpu: &Arc<Gpu>, m: &mesh::Mesh, runs: usize) -> Result<(Table, Points)> {
    let truth = torus_truth(m);
    let mut t = Table::new(
        "variants",
        vec![
            Column::new("variant", "variant"),
            Column::new("k1 RMS vs analytic", "k1_rms_vs_analytic"),
            Column::new("k2 RMS vs analytic", "k2_rms_vs_analytic"),
            Column::new("H NRMSE vs f64 ref", "h_nrmse_vs_f64_ref"),
            Column::new("kernel ms", "kernel_ms"),
            Column::new("wall ms", "wall_ms"),
        ],
    );
    let refs = |compat: Compat| {
        let o = CurvatureOptions {
            compat,
            ..Default::default()
        };
        crate::cpu::curvature::estimate(m, &o).0
    };
    let ref_exact = refs(Compat::Exact);
    let ref_compat = refs(Compat::Trimesh2);
    let mut points = Vec::new();
    for v in variants() {
        let res = match measure(gpu, m, v, runs) {
            Ok(res) => res,
            // a variant the device lacks a feature for (native float
            // atomics, fp64) is a row saying so, not the end of the table
            Err(Error::DeviceUnsupported { what, .. }) => {
                let mut cells = vec![Cell::text(label(&v))];
                cells.extend((1..6).map(|_| Cell::empty()));
                t.rows.push(Row {
                    cells,
                    note: Some(format!("not on this device: {what}")),
                });
                continue;
            }
            Err(e) => return Err(e),
        };
        let reference = if v.compat == Compat::Exact {
            &ref_exact
        } else {
            &ref_compat
        };
        let (e1, e2) = analytic_rms(&res.field, &truth);
        let eh = nrmse(&res.field.mean(), &reference.mean());
        points.push((label(&v), res.kernel_ms, e1));
        t.rows.push(Row::new(vec![
            Cell::text(label(&v)),
            e3(e1),
            e3(e2),
            Cell::sci(eh, 2),
            ms(res.kernel_ms),
            ms(res.wall_ms),
        ]));
    }
    t.rows.push(cpu_row(m, &truth));
    Ok((t, points))
}

/// The f64 CPU reference (exact solve, one thread): its errors and time.
fn cpu_row(m: &mesh::Mesh, truth: &[(f64, f64)]) -> Row {
    let clock = Instant::now();
    let (cf, _) = crate::cpu::curvature::estimate(m, &CurvatureOptions::default());
    let cpu_ms = clock.elapsed().as_secs_f64() * 1e3;
    let (e1, e2) = analytic_rms(&cf, truth);
    Row::new(vec![
        Cell::text("cpu reference f64 exact (1 thread)"),
        e3(e1),
        e3(e2),
        Cell::num(0.0, "0".into()),
        Cell::shown("-", serde_json::Value::Null),
        ms(cpu_ms),
    ])
}

/// The refinement sweep over [`REFINEMENT`]: k1 errors of exact f32, exact
/// f64 and trimesh2 f32 with their (h, error) series.
fn refinement_table(gpu: &Arc<Gpu>, runs: usize) -> Result<(Table, Series)> {
    let mut t = Table::new(
        "refinement",
        vec![
            Column::new("vertices", "vertices"),
            Column::new("h", "h"),
            Column::new("exact f32", "exact_f32_k1_rms"),
            Column::new("exact f64", "exact_f64_k1_rms"),
            Column::new("trimesh2 f32", "trimesh2_f32_k1_rms"),
            Column::new("exact f32 kernel ms", "exact_f32_kernel_ms"),
            Column::new("exact f64 kernel ms", "exact_f64_kernel_ms"),
        ],
    );
    let mut series: Series = ["exact f32", "exact f64", "trimesh2 f32"]
        .iter()
        .map(|s| (s.to_string(), Vec::new()))
        .collect();
    for nn in REFINEMENT {
        let (row, h, errs) = refinement_row(gpu, nn, runs)?;
        for (s, e) in series.iter_mut().zip(errs) {
            s.1.push((h, e));
        }
        t.rows.push(row);
    }
    Ok((t, series))
}

/// One refinement step, a torus of about `nn` vertices: its row, edge
/// length h and the three k1 errors.
fn refinement_row(gpu: &Arc<Gpu>, nn: usize, runs: usize) -> Result<(Row, f64, [f64; 3])> {
    let (nu, nv) = mesh::torus_resolution_for(nn);
    let m = mesh::torus(1.0, 0.4, nu, nv);
    let truth = torus_truth(&m);
    let h = 2.0 * std::f64::consts::PI * 0.4 / nv as f64;
    let d = CurvatureOptions::default();
    let a = measure(gpu, &m, d, runs.min(3))?;
    let b = measure(
        gpu,
        &m,
        CurvatureOptions {
            precision: Precision::F64,
            ..d
        },
        runs.min(3),
    )?;
    let c = measure(
        gpu,
        &m,
        CurvatureOptions {
            compat: Compat::Trimesh2,
            ..d
        },
        1,
    )?;
    let errs = [
        analytic_rms(&a.field, &truth).0,
        analytic_rms(&b.field, &truth).0,
        analytic_rms(&c.field, &truth).0,
    ];
    let row = Row::new(vec![
        Cell::int(m.n_vertices()),
        Cell::num(h, format!("{h:.4}")),
        e3(errs[0]),
        e3(errs[1]),
        e3(errs[2]),
        ms(a.kernel_ms),
        ms(b.kernel_ms),
    ]);
    Ok((row, h, errs))
}
