//! `shapecue report isosurface`: (1) extraction + fusion time of every
//! fusion variant on the procedural fields at 128³ … 512³ (up to
//! `max_resolution`) and the bundled buckyball at a voxel value, with the
//! mesh quality each leaves; (2) the
//! resolution sweep 64³ … `max_resolution`³ of the sphere and torus SDFs:
//! extraction time, curvature time (f32 and f64, on the device, no host
//! round trip) and the RMS error of k1, k2 against the analytic values,
//! relative to 1/r (resolution is an accuracy/time trade-off).

use super::metrics::{analytic_rms, measure_isosurface, median};
use super::{Block, Cell, Chart, Column, Report, Row, Table};
use crate::error::Result;
use crate::gpu::Gpu;
use crate::spec::curvature::{CurvatureOptions, Precision};
use crate::spec::marching_cubes::IsoNormals;
use crate::spec::vertex_fusion::Fusion;
use crate::stages::marching_cubes::{self as mcs, Isosurfacer};
use crate::volume::sdf::{self, Sdf};
use std::sync::Arc;

/// The report's sizes.
#[derive(Clone, Copy, Debug)]
pub struct IsosurfaceReportOptions {
    /// Largest grid of the extraction table and the resolution sweep.
    pub max_resolution: usize,
    /// Timed runs per measurement (medians).
    pub runs: usize,
}

impl Default for IsosurfaceReportOptions {
    fn default() -> Self {
        IsosurfaceReportOptions {
            max_resolution: 512,
            runs: 5,
        }
    }
}

/// The curvature variants of the resolution sweep: name and options.
const SWEEP: [(&str, Precision, IsoNormals); 3] = [
    ("f32 mesh normals", Precision::F32, IsoNormals::Mesh),
    ("f32 gradient normals", Precision::F32, IsoNormals::Gradient),
    ("f64 gradient normals", Precision::F64, IsoNormals::Gradient),
];

fn ms(v: f64) -> Cell {
    Cell::num(v, format!("{v:.2}"))
}

/// Measures the report on `gpu`.
///
/// # Errors
/// Device failures.
pub fn report(gpu: &Arc<Gpu>, o: IsosurfaceReportOptions) -> Result<Report> {
    let mut r = Report::new("isosurface", gpu.info.name.clone());
    r.text(format!(
        "device: {} ({})\n\n\
         ## Extraction + fusion (volume on the device; median kernel ms / wall ms)\n\
         Against VTK's Flying Edges: `scripts/isosurface-table.py` times both on the same \
         volumes in the same run and gives N× faster = Flying Edges' ms ÷ shapecue's \
         (docs/notes/peer-comparisons.md); this report times shapecue alone.",
        gpu.info.name, gpu.info.platform,
    ));
    let (t, chart) = extraction(gpu, o)?;
    r.blocks.push(Block::Table(t));
    r.charts.push(chart);

    r.text("\n## Resolution sweep: curvature of the fused isosurface vs analytic");
    let sweep = resolution_sweep(gpu, o)?;
    r.blocks.push(Block::Table(sweep.table));
    r.text(
        "\n(k errors: RMS of k − k_analytic over the vertices, × r (sphere r = 0.8, torus tube \
         r = 0.25); extraction uses --fusion direct; curvature kernel ms include dcurv and, for \
         gradient normals, the override pass)",
    );
    r.charts.push(Chart::Scatter {
        title: "Isosurface curvature: k1 error (× r) against curvature kernel time".into(),
        x_label: "median curvature kernel ms".into(),
        y_label: "k1 RMS error × r".into(),
        points: sweep.points,
    });
    r.charts.push(Chart::Convergence {
        title: "Resolution sweep: k1 error (× r) against grid spacing h".into(),
        x_label: "h (grid spacing)".into(),
        y_label: "k1 RMS error × r".into(),
        series: sweep.series,
    });
    Ok(r)
}

/// The extraction table's volumes: name, volume and isovalue.
fn extraction_inputs(max_res: usize) -> Vec<(String, crate::volume::Volume, f32)> {
    let mut inputs = Vec::new();
    for (kind, res) in [
        (Sdf::Sphere, 128),
        (Sdf::Sphere, 256),
        (Sdf::Gyroid, 128),
        (Sdf::Gyroid, 256),
        (Sdf::Gyroid, 512),
    ] {
        if res <= max_res {
            let name = format!("{kind:?} {res}³").to_lowercase();
            inputs.push((name, sdf::sdf(kind, res), 0.0));
        }
    }
    // The bundled buckyball (32³ u8) at 51, a voxel value: the exact-hit case.
    if let Ok(b) = crate::volume::load(
        std::path::Path::new(concat!(env!("CARGO_MANIFEST_DIR"), "/data/bucky.nhdr")),
        None,
    ) {
        inputs.push(("bucky 32³ @51".into(), b, 51.0));
    }
    inputs
}

/// Extraction + fusion of every fusion variant on each input: the table and
/// its bar chart of kernel ms.
fn extraction(gpu: &Arc<Gpu>, o: IsosurfaceReportOptions) -> Result<(Table, Chart)> {
    let col = Column::new;
    let mut t = Table::new(
        "extraction",
        vec![
            col("volume", "volume"),
            col("fuse", "fusion"),
            col("kernel", "kernel_ms"),
            col("wall", "wall_ms"),
            col("soup v", "soup_vertices"),
            col("vertices", "vertices"),
            col("faces", "faces"),
            col("hits", "exact_hits"),
            col("dup pos", "duplicate_positions"),
            col("collapse", "collapsed_faces"),
            col("boundary", "boundary_edges"),
            col("nonmanif", "nonmanifold_edges"),
            col("euler", "euler"),
        ],
    );
    let mut bars: Vec<(String, Vec<f64>)> = Fusion::ALL
        .iter()
        .map(|f| (f.name().to_string(), Vec::new()))
        .collect();
    let mut groups = Vec::new();
    for (name, vol, iso) in extraction_inputs(o.max_resolution) {
        let mut ex = Isosurfacer::new(gpu.clone(), &vol)?;
        groups.push(name.clone());
        for (i, fusion) in Fusion::ALL.into_iter().enumerate() {
            let (k, wall, st) = measure_isosurface(&mut ex, iso, fusion, o.runs)?;
            let (p, f) = ex.read_index_space()?;
            let q = crate::mesh::quality(&p, &f);
            bars[i].1.push(k);
            t.rows.push(Row::new(vec![
                Cell::text(name.clone()),
                Cell::text(fusion.name()),
                ms(k),
                ms(wall),
                Cell::int(st.soup_vertices),
                Cell::int(st.vertices),
                Cell::int(st.faces),
                Cell::int(st.exact_hits),
                Cell::int(q.vertices - q.unique_positions),
                Cell::int(q.collapsed_faces),
                Cell::int(q.boundary_edges),
                Cell::int(q.nonmanifold_edges),
                Cell::int(q.euler),
            ]));
        }
    }
    let chart = Chart::Bars {
        title: "Extraction + fusion: median kernel ms per fusion variant".into(),
        y_label: "kernel ms".into(),
        log_y: true,
        groups,
        series: bars,
    };
    Ok((t, chart))
}

/// The resolution sweep's table and the points of its two charts.
struct Sweep {
    /// One row per surface and resolution.
    table: Table,
    /// (label, curvature ms, k1 error) per surface, resolution and variant.
    points: Vec<(String, f64, f64)>,
    /// (h, k1 error) per surface and variant.
    series: Vec<(String, Vec<(f64, f64)>)>,
}

/// The resolution sweep's columns: per [`SWEEP`] variant, ms and k errors.
fn sweep_columns() -> Vec<Column> {
    let col = Column::new;
    let mut cols = vec![
        col("surface", "surface"),
        col("res", "res"),
        col("faces", "faces"),
        col("extract ms", "extract_ms"),
    ];
    for (name, _, _) in SWEEP {
        let key = name.replace(' ', "_");
        cols.push(col(&format!("{name} ms"), &format!("{key}_ms")));
        cols.push(col(
            &format!("{name} k1 err"),
            &format!("{key}_k1_rms_times_r"),
        ));
        cols.push(col(
            &format!("{name} k2 err"),
            &format!("{key}_k2_rms_times_r"),
        ));
    }
    cols.push(Column::hidden("h"));
    cols
}

/// The sphere and torus SDFs from 64³ to `max_resolution`³: extraction and
/// each curvature variant's time and error against the analytic values.
fn resolution_sweep(gpu: &Arc<Gpu>, o: IsosurfaceReportOptions) -> Result<Sweep> {
    let mut sweep = Sweep {
        table: Table::new("resolution_sweep", sweep_columns()),
        points: Vec::new(),
        series: Vec::new(),
    };
    for kind in [Sdf::Sphere, Sdf::Torus] {
        let surface = format!("{kind:?}").to_lowercase();
        let first = sweep.series.len();
        sweep.series.extend(
            SWEEP
                .iter()
                .map(|(name, _, _)| (format!("{surface} {name}"), Vec::new())),
        );
        let mut res = 64;
        while res <= o.max_resolution {
            sweep_row(gpu, &mut sweep, kind, res, first, o.runs)?;
            res *= 2;
        }
    }
    Ok(sweep)
}

/// One row of the sweep: the `kind` SDF at `res`³, its variants' series
/// starting at `first`.
fn sweep_row(
    gpu: &Arc<Gpu>,
    sweep: &mut Sweep,
    kind: Sdf,
    res: usize,
    first: usize,
    runs: usize,
) -> Result<()> {
    let surface = format!("{kind:?}").to_lowercase();
    let vol = sdf::sdf(kind, res);
    let h = vol.spacing[0];
    let mut ex = Isosurfacer::new(gpu.clone(), &vol)?;
    let (k, _, st) = measure_isosurface(&mut ex, 0.0, Fusion::Direct, runs)?;
    let mesh = ex.read()?;
    let (rad, truth) = analytic(kind, &mesh.positions);
    let mut cells = vec![
        Cell::text(surface.clone()),
        Cell::int(res),
        Cell::int(st.faces),
        ms(k),
    ];
    for (i, (name, precision, normals)) in SWEEP.into_iter().enumerate() {
        let opts = CurvatureOptions {
            precision,
            ..Default::default()
        };
        let mut times = Vec::new();
        let (mut est, _) = mcs::curvature(&ex, opts, normals)?;
        for _ in 0..runs.max(1) {
            times.push(est.run()?.kernel_ms);
        }
        let f = est.read()?;
        let (e1, e2) = analytic_rms(&f, &truth);
        let (e1, e2, cm) = (e1 * rad, e2 * rad, median(&mut times));
        sweep
            .points
            .push((format!("{surface} {res}³ {name}"), cm, e1));
        sweep.series[first + i].1.push((h, e1));
        cells.push(ms(cm));
        cells.push(Cell::num(e1, format!("{e1:.3e}")));
        cells.push(Cell::num(e2, format!("{e2:.3e}")));
    }
    cells.push(Cell::num(h, String::new()));
    sweep.table.rows.push(Row::new(cells));
    Ok(())
}

/// The radius errors are scaled by and the analytic (k1, k2) at each position.
fn analytic(kind: Sdf, positions: &[[f64; 3]]) -> (f64, Vec<(f64, f64)>) {
    match kind {
        Sdf::Torus => (
            sdf::TORUS_TUBE,
            positions.iter().map(|&p| sdf::torus_curvature(p)).collect(),
        ),
        _ => (
            sdf::SPHERE_RADIUS,
            positions
                .iter()
                .map(|&p| sdf::sphere_curvature(p))
                .collect(),
        ),
    }
}
