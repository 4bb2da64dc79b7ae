//! What accuracy costs in time: error metrics (RMSE, NRMSE, analytic
//! errors, medians) and timed runs of the stages and of the front door,
//! shared by the report tables, the tests and the benches.

use crate::error::Result;
use crate::gpu::Gpu;
use crate::mesh::{self, Mesh};
use crate::spec::curvature::{
    Accumulate, Compat, CurvatureField, CurvatureOptions, Lanes, Precision,
};
use crate::spec::timing::Timing;
use crate::stages::curvature::CurvatureEstimator;
use std::sync::Arc;

/// Root-mean-square difference.
pub fn rmse(a: &[f64], b: &[f64]) -> f64 {
    assert_eq!(a.len(), b.len(), "rmse of slices of different lengths");
    let n = a.len().max(1) as f64;
    (a.iter().zip(b).map(|(x, y)| (x - y).powi(2)).sum::<f64>() / n).sqrt()
}

/// RMS error normalized by the reference's range; for a (nearly) constant
/// attribute, whose range says nothing, by its mean magnitude instead
/// (whichever is larger). Multiply by 100 for percent.
pub fn nrmse(a: &[f64], reference: &[f64]) -> f64 {
    let (lo, hi) = reference
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(l, h), &x| {
            (l.min(x), h.max(x))
        });
    let mean_abs = reference.iter().map(|x| x.abs()).sum::<f64>() / reference.len().max(1) as f64;
    let norm = (hi - lo).max(mean_abs);
    if norm > 0.0 {
        rmse(a, reference) / norm
    } else {
        rmse(a, reference)
    }
}

/// RMS error of (k1, k2) against analytic values at each vertex.
pub fn analytic_rms(f: &CurvatureField, truth: &[(f64, f64)]) -> (f64, f64) {
    let t1: Vec<f64> = truth.iter().map(|t| t.0).collect();
    let t2: Vec<f64> = truth.iter().map(|t| t.1).collect();
    (rmse(&f.k1, &t1), rmse(&f.k2, &t2))
}

/// Analytic curvature of the report's torus (R = 1, r = 0.4) at its vertices.
pub fn torus_truth(m: &Mesh) -> Vec<(f64, f64)> {
    m.positions
        .iter()
        .map(|&p| mesh::torus_curvature(1.0, 0.4, p))
        .collect()
}

/// Median of a list of times (the mean of the middle two for an even
/// count; 0 for an empty list): the medians a stage's repeated runs
/// report (`shapecue report`, `shapecue render`'s per-view medians, the edges command's frames).
pub fn median(v: &mut [f64]) -> f64 {
    if v.is_empty() {
        return 0.0;
    }
    v.sort_by(|a, b| a.total_cmp(b));
    let n = v.len();
    if n % 2 == 1 {
        v[n / 2]
    } else {
        0.5 * (v[n / 2 - 1] + v[n / 2])
    }
}

/// One measured variant: the field of its last run and median times.
pub struct Measured {
    /// Output of the last run.
    pub field: CurvatureField,
    /// Median kernel time (ms) over the runs, mesh already on the device.
    pub kernel_ms: f64,
    /// Median wall time (ms) of a run, upload of positions and read-back excluded.
    pub wall_ms: f64,
}

/// Runs a device variant `runs` times on `m` (after warm-up runs that pay
/// for JIT compilation and wake an idle device: at least 3 and 100 ms) and
/// returns medians.
pub fn measure(gpu: &Arc<Gpu>, m: &Mesh, opts: CurvatureOptions, runs: usize) -> Result<Measured> {
    let mut est = CurvatureEstimator::new(gpu.clone(), m.n_vertices(), &m.faces, opts)?;
    est.set_positions(&m.positions)?;
    // Warm-up: at least 3 runs and 100 ms (at most 50 runs). On a CPU
    // device in a virtual machine, a device that was idle (the CPU
    // reference before the first variant) runs its first tens of
    // milliseconds slower (the report's first variant, alone: 9.2-9.5 ms
    // median on a 40k-vertex torus with one warm-up run, against 4.95 in a
    // process of its own), which the comparison should not charge to it.
    let t0 = std::time::Instant::now();
    for i in 0..50 {
        if i >= 3 && t0.elapsed().as_secs_f64() >= 0.1 {
            break;
        }
        est.run()?;
    }
    let (mut k, mut w) = (Vec::new(), Vec::new());
    for _ in 0..runs.max(1) {
        let t = est.run()?;
        k.push(t.kernel_ms);
        w.push(t.wall_ms);
    }
    Ok(Measured {
        field: est.read()?,
        kernel_ms: median(&mut k),
        wall_ms: median(&mut w),
    })
}

/// A variant's name, e.g. `atomic f32 exact` or `gather f64 exact no-dcurv`
/// (the report's rows; the bench uses it with dashes).
pub fn label(o: &CurvatureOptions) -> String {
    format!(
        "{} {} {}{}",
        o.accumulate.name(),
        match o.precision {
            Precision::F32 => "f32",
            Precision::F64 => "f64",
        },
        match o.compat {
            Compat::Exact => "exact",
            Compat::Trimesh2 => "trimesh2",
        },
        if o.dcurv { "" } else { " no-dcurv" }
    ) + &match o.lanes {
        // explicit lane counts; auto is the device's default
        Lanes::Auto => String::new(),
        Lanes::Fixed(1) => " 1-lane".to_string(),
        Lanes::Fixed(n) => format!(" {n}-lanes"),
    }
}

/// The variants the report and the criterion bench compare, default first.
pub fn variants() -> Vec<CurvatureOptions> {
    // The paper's compare-and-swap scheme first, then the others beside it
    // (gather is the library's default).
    let d = CurvatureOptions {
        accumulate: Accumulate::Atomic,
        ..CurvatureOptions::default()
    };
    vec![
        d,
        // the compare-and-swap scheme one face per work-item (the paper's
        // form): what SIMD lanes gain it on a CPU device
        CurvatureOptions {
            lanes: Lanes::Fixed(1),
            ..d
        },
        CurvatureOptions { dcurv: false, ..d },
        CurvatureOptions {
            accumulate: Accumulate::Gather,
            ..d
        },
        // the gather scheme one face per work-item: what explicit SIMD lanes gain
        CurvatureOptions {
            accumulate: Accumulate::Gather,
            lanes: Lanes::Fixed(1),
            ..d
        },
        // the device's own float atomic add, where it has one
        CurvatureOptions {
            accumulate: Accumulate::AtomicNative,
            ..d
        },
        CurvatureOptions {
            precision: Precision::F64,
            ..d
        },
        CurvatureOptions {
            accumulate: Accumulate::Gather,
            precision: Precision::F64,
            ..d
        },
        CurvatureOptions {
            compat: Compat::Trimesh2,
            ..d
        },
    ]
}

/// Median kernel and wall ms of `runs` extractions (after one warm-up that
/// pays for JIT compilation), and the stats of the last.
pub fn measure_isosurface(
    ex: &mut crate::stages::marching_cubes::Isosurfacer,
    iso: f32,
    fusion: crate::spec::vertex_fusion::Fusion,
    runs: usize,
) -> Result<(f64, f64, crate::stages::marching_cubes::IsoStats)> {
    let mut st = ex.extract(iso, fusion)?;
    let (mut k, mut w) = (Vec::new(), Vec::new());
    for _ in 0..runs.max(1) {
        st = ex.extract(iso, fusion)?;
        k.push(st.timing.kernel_ms);
        w.push(st.timing.wall_ms);
    }
    Ok((median(&mut k), median(&mut w), st))
}

/// Timings of `runs` calls of the front door's [`crate::isosurface_on`]
/// with `opts` (each uploads the volume and extracts once; its
/// [`crate::stages::marching_cubes::IsoStats::timing`] is the extraction's,
/// with the volume on the device), for the medians of
/// `shapecue isosurface --runs`. Curvature and gradient normals are left
/// out: the runs time the extraction.
pub fn isosurface_runs(
    gpu: &Arc<Gpu>,
    volume: &crate::volume::Volume,
    iso: f32,
    opts: &crate::IsoOptions,
    runs: usize,
) -> Result<Vec<crate::spec::timing::Timing>> {
    let opts = crate::IsoOptions {
        curvature: None,
        gradient_normals: false,
        ..*opts
    };
    (0..runs)
        .map(|_| Ok(crate::isosurface_on(gpu, volume, iso, &opts)?.stats.timing))
        .collect()
}

/// The `--runs` keys of a command's JSON stats (`shapecue curvature` and
/// `isosurface`): the count, kernel and wall medians and minima, the median
/// of each pass, and an estimate of the driver's compilation at first
/// launch (first run's wall − median wall).
pub fn runs_stats(stats: &mut serde_json::Value, timed: &[Timing], first_wall_ms: f64) {
    let mut kernel: Vec<f64> = timed.iter().map(|t| t.kernel_ms).collect();
    let mut wall: Vec<f64> = timed.iter().map(|t| t.wall_ms).collect();
    let (kmin, wmin) = (
        kernel.iter().copied().fold(f64::INFINITY, f64::min),
        wall.iter().copied().fold(f64::INFINITY, f64::min),
    );
    let wall_median = median(&mut wall);
    // Each step once (a step that ran several times, such as the scan, is
    // one entry with its summed time), in the order it first ran.
    let mut seen = Vec::new();
    let per_pass: Vec<serde_json::Value> = timed
        .first()
        .map(|t| &t.steps[..])
        .unwrap_or_default()
        .iter()
        .filter(|s| {
            let first = !seen.contains(&s.step);
            seen.push(s.step);
            first
        })
        .map(|s| {
            let mut ms: Vec<f64> = timed.iter().map(|t| t.ms(&[s.step])).collect();
            serde_json::json!({ "pass": s.step.name(), "kernel_ms": median(&mut ms) })
        })
        .collect();
    stats["runs"] = serde_json::json!(timed.len());
    stats["kernel_median_ms"] = serde_json::json!(median(&mut kernel));
    stats["kernel_min_ms"] = serde_json::json!(kmin);
    stats["wall_median_ms"] = serde_json::json!(wall_median);
    stats["wall_min_ms"] = serde_json::json!(wmin);
    stats["passes_median"] = serde_json::Value::Array(per_pass);
    stats["first_launch_compile_ms"] = serde_json::json!((first_wall_ms - wall_median).max(0.0));
}
