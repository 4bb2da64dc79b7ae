//! `shapecue report strokes`: on the torus SDF (tube radius r, κ1 = 1/r
//! with d1 around the tube), per grid resolution and sampling distance, the
//! relative κ1 error and the angle between d1 and the tube's cross-section
//! direction at the seeds (median and 95th percentile), beside the kernel
//! ms of the whole run (seed spacing fixed at 0.05 so the seed counts
//! compare).

use super::{Block, Cell, Chart, Column, Report, Row, Table};
use crate::error::Result;
use crate::gpu::Gpu;
use crate::spec::sdf_lines::{Sampling, SdfLineOptions, Seed};
use crate::stages::sdf_lines::SdfLines;
use crate::volume::Volume;
use crate::volume::sdf::{Sdf, TORUS_TUBE, sdf, torus_curvature};
use std::sync::Arc;

/// The report's sizes.
#[derive(Clone, Copy, Debug)]
pub struct StrokesReportOptions {
    /// Largest grid of the sweep (32, 64, 128, 256 up to this).
    pub max_resolution: usize,
}

impl Default for StrokesReportOptions {
    fn default() -> Self {
        StrokesReportOptions {
            max_resolution: 256,
        }
    }
}

/// The `q` quantile of `v` (nearest rank; NaN for none).
fn quantile(v: &mut [f64], q: f64) -> f64 {
    if v.is_empty() {
        return f64::NAN;
    }
    v.sort_by(f64::total_cmp);
    v[((v.len() - 1) as f64 * q).round() as usize]
}

/// Measures the report on `gpu`.
///
/// # Errors
/// Device failures.
pub fn report(gpu: &Arc<Gpu>, o: StrokesReportOptions) -> Result<Report> {
    let mut r = Report::new("strokes", gpu.info.name.clone());
    r.text(format!(
        "torus SDF (R 0.6, r {TORUS_TUBE}: κ1 = 1/r = {:.1}, d1 around the tube); seed spacing 0.05",
        1.0 / TORUS_TUBE
    ));
    let mut t = sweep_table();
    let mut points = Vec::new();
    for res in [32usize, 64, 128, 256] {
        if res > o.max_resolution.max(32) {
            break;
        }
        let vol = sdf(Sdf::Torus, res);
        for hv in [1.0, 2.0, 4.0] {
            let (row, point) = sweep_row(gpu, &vol, res, hv)?;
            t.rows.push(row);
            points.push(point);
        }
    }
    r.blocks.push(Block::Table(t));
    r.text(
        "(errors at the thinned seeds; kernel ms from OpenCL profiling events, sweep excluded: fixed h)",
    );
    r.charts.push(Chart::Scatter {
        title: "Strokes on the torus SDF: median κ1 error against kernel time".into(),
        x_label: "kernel ms (whole run)".into(),
        y_label: "median relative κ1 error".into(),
        points,
    });
    Ok(r)
}

/// The sweep table's columns, no rows yet.
fn sweep_table() -> Table {
    let col = Column::new;
    Table::new(
        "sweep",
        vec![
            col("res", "res"),
            col("h/voxel", "h_per_voxel"),
            col("h", "h"),
            col("seeds", "seeds"),
            col("κ1 err med", "k1_rel_err_median"),
            col("κ1 err p95", "k1_rel_err_p95"),
            col("d1 ° med", "d1_err_median_deg"),
            col("d1 ° p95", "d1_err_p95_deg"),
            col("kernel ms", "kernel_ms"),
        ],
    )
}

/// One run on the torus `vol` at `res`³ with a sampling distance of `hv`
/// voxels: its row, and its (label, kernel ms, median κ1 error) point.
fn sweep_row(
    gpu: &Arc<Gpu>,
    vol: &Volume,
    res: usize,
    hv: f64,
) -> Result<(Row, (String, f64, f64))> {
    let voxel = vol.spacing[0];
    let opts = SdfLineOptions {
        sampling: Sampling::Fixed(hv * voxel),
        spacing: Some(0.05),
        ..SdfLineOptions::default()
    };
    let out = SdfLines::new(gpu.clone(), vol, &opts)?.run()?;
    let (mut ke, mut de): (Vec<f64>, Vec<f64>) = out
        .seeds
        .iter()
        .filter(|s| s.valid)
        .map(seed_errors)
        .unzip();
    let seeds = ke.len();
    let (k50, k95) = (quantile(&mut ke, 0.5), quantile(&mut ke, 0.95));
    let (d50, d95) = (quantile(&mut de, 0.5), quantile(&mut de, 0.95));
    let kms = out.stats.timing.kernel_ms;
    let voxels = if hv == 1.0 { "voxel" } else { "voxels" };
    let point = (format!("{res}³, h = {hv} {voxels}"), kms, k50);
    let row = Row::new(vec![
        Cell::int(res),
        Cell::num(hv, format!("{hv:.1}")),
        Cell::num(hv * voxel, format!("{:.4}", hv * voxel)),
        Cell::int(seeds),
        Cell::sci(k50, 2),
        Cell::sci(k95, 2),
        Cell::num(d50, format!("{d50:.3}")),
        Cell::num(d95, format!("{d95:.3}")),
        Cell::num(kms, format!("{kms:.2}")),
    ]);
    Ok((row, point))
}

/// A seed's relative κ1 error and the angle in degrees between its d1 and
/// the tube's cross-section direction.
fn seed_errors(sd: &Seed) -> (f64, f64) {
    let (k1, _) = torus_curvature(sd.p);
    let ke = ((sd.k1 - k1) / k1).abs();
    // Tube direction: normal × ring tangent (ring tangent ∝ (−y, x, 0)).
    let [x, y, _] = sd.p;
    let t = [-y, x, 0.0];
    let n = sd.n;
    let d = [
        n[1] * t[2] - n[2] * t[1],
        n[2] * t[0] - n[0] * t[2],
        n[0] * t[1] - n[1] * t[0],
    ];
    let dl = (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt();
    let dot = (d[0] * sd.d1[0] + d[1] * sd.d1[1] + d[2] * sd.d1[2]).abs() / dl;
    (ke, dot.clamp(0.0, 1.0).acos().to_degrees())
}
