//! `shapecue report pipeline`: the per-frame device pipeline of an animated
//! glTF model ([`PosePipeline`]: skin, curvature + dcurv, AO `lut`,
//! contours + suggestive contours from [`PosePipeline::front_view`]) over
//! `frames` poses of the first clip, `runs` times (after one warm-up frame
//! that pays for JIT compilation). One row per pass with its median kernel
//! ms; the two other AO levels run on the same curvatures each frame, with
//! their RMS difference from the `exact` level next to their time (accuracy
//! and cost side by side); then the median total of the default pipeline
//! (kernel sum and host wall per frame) and whether it meets the 16 ms
//! frame budget.

use super::metrics::median;
use super::{Block, Cell, Chart, Column, Report, Row, Table};
use crate::error::Result;
use crate::gpu::Gpu;
use crate::spec::ao::AoMode;
use crate::spec::feature_lines::{FamilySet, LineFamily};
use crate::spec::timing::Family;
use crate::spec::view::View;
use crate::stages::feature_lines::LineOptions;
use crate::stages::pipeline::{PassTimes, PipelineOptions, PosePipeline, clip_poses};
use std::path::Path;
use std::sync::Arc;

/// The report's sizes.
#[derive(Clone, Copy, Debug)]
pub struct PipelineReportOptions {
    /// Poses sampled from the first clip.
    pub frames: usize,
    /// Timed runs over the poses (medians).
    pub runs: usize,
}

impl Default for PipelineReportOptions {
    fn default() -> Self {
        PipelineReportOptions {
            frames: 30,
            runs: 3,
        }
    }
}

/// The model the pipeline report times when none is given.
pub fn default_model() -> std::path::PathBuf {
    super::shared_data().join("animations/gltf/BrainStem.glb")
}

/// Measures the report of each model in `models` on `gpu` (one report,
/// one table per model).
///
/// # Errors
/// A model that cannot be loaded or has no clip, device failures.
pub fn report(gpu: &Arc<Gpu>, models: &[&Path], o: PipelineReportOptions) -> Result<Report> {
    let mut r = Report::new("pipeline", gpu.info.name.clone());
    for (i, gltf) in models.iter().enumerate() {
        model(&mut r, gpu, gltf, i, o)?;
    }
    Ok(r)
}

/// The table keys of the models, in order (a JSON key names its table).
const KEYS: [&str; 8] = [
    "passes", "passes_2", "passes_3", "passes_4", "passes_5", "passes_6", "passes_7", "passes_8",
];

/// The keys of the line-family tables, one per model.
const LINE_KEYS: [&str; 8] = [
    "lines", "lines_2", "lines_3", "lines_4", "lines_5", "lines_6", "lines_7", "lines_8",
];

/// The most models one report times.
pub const MAX_MODELS: usize = KEYS.len();

/// Times the pipeline on one model and appends its text, tables and chart
/// to `r` (`index`: the model's place, which keys its tables).
fn model(
    r: &mut Report,
    gpu: &Arc<Gpu>,
    gltf: &Path,
    index: usize,
    o: PipelineReportOptions,
) -> Result<()> {
    let (frames, runs) = (o.frames.max(1), o.runs.max(1));
    let m = crate::mesh::skinned::load_gltf(gltf)?;
    let p = PosePipeline::new(gpu.clone(), &m, PipelineOptions::default())?;
    let poses = clip_poses(&m, frames)?;
    let (view, size) = (p.front_view(), p.feature_size());
    let mut b = Bench {
        p,
        poses,
        view,
        size,
    };
    let mut fr = frame_runs(&mut b, runs)?;
    let fam_ms = family_runs(&mut b)?;
    let name = gltf.file_name().map_or_else(
        || gltf.display().to_string(),
        |n| n.to_string_lossy().into_owned(),
    );
    r.text(format!(
        "{}Per-frame device pipeline on {name}: {} vertices, {} faces, {} poses × {runs} runs; \
         device: {} ({} CUs); AO radius {:.4} (0.1 × RMS radius), feature size {size:.4}, \
         {} segments in the last frame\n",
        if index > 0 { "\n" } else { "" },
        m.rest.positions.len(),
        m.rest.faces.len(),
        b.poses.len(),
        gpu.info.name,
        gpu.info.compute_units,
        b.p.ao_radius(),
        fr.t.last().map_or(0, |x| x.segments),
    ));
    let passes = pass_table(index, &name, &mut fr);
    r.blocks.push(Block::Table(passes.table));
    r.text("\nFeature-line kernels per view (pose terms once per pose), by family:\n".to_string());
    r.blocks
        .push(Block::Table(lines_table(index, &name, &fam_ms)));
    let (kernel, wall) = (passes.kernel, passes.wall);
    let verdict = |ms: f64| if ms <= 16.0 { "met" } else { "NOT met" };
    r.text(format!(
        "\nwall ms per frame (median, matrices up, segments back): {wall:.3}\n\
         16 ms frame budget: {} by the kernel total ({kernel:.2} ms), {} by the wall time ({wall:.2} ms)",
        verdict(kernel),
        verdict(wall)
    ));
    r.charts.push(Chart::Bars {
        title: format!(
            "Per-frame device pipeline on {name}: median kernel ms per pass (total {kernel:.2} ms)"
        ),
        y_label: "kernel ms".into(),
        log_y: false,
        groups: passes.bars.0,
        series: vec![("median kernel ms".into(), passes.bars.1)],
    });
    Ok(())
}

/// A model's pipeline, its poses, and the view and feature size its lines
/// are found with.
struct Bench {
    p: PosePipeline,
    poses: Vec<Vec<f32>>,
    view: View,
    size: f32,
}

/// The timed frames of the default pipeline, with the other AO levels run
/// on the same curvatures beside them.
struct FrameRuns {
    /// Each frame's pass times.
    t: Vec<PassTimes>,
    /// Kernel ms of the `poly` AO level, per frame.
    poly: Vec<f64>,
    /// Kernel ms of the `exact` AO level, per frame.
    exact: Vec<f64>,
    /// Squared differences of `poly` from `exact`, over vertices and frames.
    se_poly: f64,
    /// Squared differences of `lut` from `exact`, over vertices and frames.
    se_lut: f64,
    /// Vertices × frames the squared differences sum over.
    n: usize,
}

/// One warm-up frame (and AO level), then `runs` times every pose: the
/// default pipeline's times and the AO levels' times and differences.
fn frame_runs(b: &mut Bench, runs: usize) -> Result<FrameRuns> {
    let (p, view, size, lines) = (&mut b.p, b.view, b.size, LineOptions::default());
    p.frame(&b.poses[0], view, size, lines)?;
    for mode in AoMode::ALL {
        p.ao(mode)?;
    }
    let mut fr = FrameRuns {
        t: Vec::new(),
        poly: Vec::new(),
        exact: Vec::new(),
        se_poly: 0.0,
        se_lut: 0.0,
        n: 0,
    };
    for _ in 0..runs {
        for mats in &b.poses {
            let (_, times) = p.frame(mats, view, size, lines)?;
            fr.t.push(times);
            let lut = p.read_ao()?;
            fr.poly.push(p.ao(AoMode::Poly)?);
            let pv = p.read_ao()?;
            fr.exact.push(p.ao(AoMode::Exact)?);
            let ev = p.read_ao()?;
            for ((l, q), e) in lut.iter().zip(&pv).zip(&ev) {
                fr.se_lut += f64::from(l - e).powi(2);
                fr.se_poly += f64::from(q - e).powi(2);
            }
            fr.n += ev.len();
        }
    }
    Ok(fr)
}

/// Each curvature line family alone, then every family at once: the
/// median feature-lines kernel ms of one view per pose (the pose terms once
/// per pose), over the same poses.
fn family_runs(b: &mut Bench) -> Result<Vec<(String, f64)>> {
    let mut fam_ms: Vec<(String, f64)> = Vec::new();
    let every = FamilySet(LineFamily::ALL.iter().fold(0, |m, f| m | f.bit()));
    let sets: Vec<(String, FamilySet)> = LineFamily::ALL[2..]
        .iter()
        .map(|f| (format!("lines: {}", f.name()), FamilySet::of(&[*f])))
        .chain(std::iter::once(("lines: every family".to_string(), every)))
        .collect();
    for (label, set) in sets {
        let opts = LineOptions::default().with_families(set);
        let mut ms = Vec::new();
        for mats in &b.poses {
            b.p.skin(mats)?;
            b.p.curvature()?;
            let (_, st) = b.p.lines(b.view, b.size, opts)?;
            ms.push(st.timing.family_ms(Family::FeatureLines));
        }
        fam_ms.push((label, median(&mut ms)));
    }
    Ok(fam_ms)
}

/// The pass table of one model, its bars and the median totals.
struct Passes {
    table: Table,
    /// (pass, median kernel ms), the total left out.
    bars: (Vec<String>, Vec<f64>),
    /// Median kernel total per frame.
    kernel: f64,
    /// Median host wall per frame.
    wall: f64,
}

/// One row per pass of the model called `name`: median kernel ms and,
/// for the AO levels, the RMS difference from `exact`; then the total.
fn pass_table(index: usize, name: &str, fr: &mut FrameRuns) -> Passes {
    let t = &fr.t;
    let rms = |se: f64| (se / fr.n.max(1) as f64).sqrt();
    let med = |f: &dyn Fn(&PassTimes) -> f64| median(&mut t.iter().map(f).collect::<Vec<_>>());
    let mut table = Table::new(
        KEYS[index.min(KEYS.len() - 1)],
        vec![
            Column::new("pass", "pass"),
            Column::new("median kernel ms", "kernel_ms"),
            Column::new("AO RMS vs exact", "ao_rms_vs_exact"),
            Column::hidden("model"),
        ],
    );
    let mut bars = (Vec::new(), Vec::new());
    let mut row = |pass: &str, ms: f64, err: Cell| {
        if !pass.starts_with("**") {
            bars.0.push(pass.to_string());
            bars.1.push(ms);
        }
        table.rows.push(Row::new(vec![
            Cell::text(pass.trim_matches('*')),
            Cell::num(ms, format!("{ms:.3}")),
            err,
            Cell::text(name.to_string()),
        ]));
    };
    let e2 = |v: f64| Cell::sci(v, 2);
    row(
        "skin",
        med(&|x| x.family_ms(Family::Skinning)),
        Cell::empty(),
    );
    row(
        "curvature+dcurv",
        med(&|x| x.family_ms(Family::Curvature)),
        Cell::empty(),
    );
    row(
        "ao lut",
        med(&|x| x.family_ms(Family::Ao)),
        e2(rms(fr.se_lut)),
    );
    row("ao poly", median(&mut fr.poly), e2(rms(fr.se_poly)));
    row(
        "ao exact",
        median(&mut fr.exact),
        Cell::shown("0 (reference)", serde_json::json!(0.0)),
    );
    row(
        "contours+suggestive",
        med(&|x| x.family_ms(Family::FeatureLines)),
        Cell::empty(),
    );
    let (kernel, wall) = (med(&|x| x.kernel_ms), med(&|x| x.wall_ms));
    row(
        "**total (skin+curv+dcurv+ao lut+lines)**",
        kernel,
        Cell::empty(),
    );
    // The total's name is bold in the table, plain in the JSON.
    if let Some(last) = table.rows.last_mut() {
        last.cells[0].text = "**total (skin+curv+dcurv+ao lut+lines)**".into();
    }
    Passes {
        table,
        bars,
        kernel,
        wall,
    }
}

/// The line families, beside the frame (not in its total): the
/// feature-lines kernels of one view per pose, each family alone, then
/// every family at once.
fn lines_table(index: usize, name: &str, fam_ms: &[(String, f64)]) -> Table {
    let mut lines_table = Table::new(
        LINE_KEYS[index.min(LINE_KEYS.len() - 1)],
        vec![
            Column::new("line families", "families"),
            Column::new("median kernel ms", "kernel_ms"),
            Column::hidden("model"),
        ],
    );
    for (label, ms) in fam_ms {
        lines_table.rows.push(Row::new(vec![
            Cell::text(label.trim_start_matches("lines: ")),
            Cell::num(*ms, format!("{ms:.3}")),
            Cell::text(name.to_string()),
        ]));
    }
    lines_table
}
