//! `shapecue report lines-batch`: views per second of line drawings from
//! many cameras in one run, as `shapecue lines MESH --views N --out DIR
//! --npz` makes them (exact visibility, an SVG and the segment pieces as
//! NPZ per view), split into the per-pose part (one-rings, normals,
//! curvature and its derivative, the feature size, the BVH: once) and the
//! per-view part (the line kernels, their visibility and chains, the SVG
//! and the NPZ: once per view), with every line family of rtsc and with
//! contours and suggestive contours only, on the meshes given and on a
//! generated mesh of about a million faces.

use super::metrics::median;
use super::{Block, Cell, Chart, Column, Report, Row, Table};
use crate::api::{
    CameraDefaults, ExecOptions, LineFiles, LinesPictureOptions, VisibleLines, fibonacci_views,
    lines_on, lines_views_scene, segment_arrays, with_consumer,
};
use crate::error::{Error, Result};
use crate::gpu::Gpu;
use crate::mesh::{self, Mesh};
use crate::scene::planner::Lifetime;
use crate::spec::feature_lines::{FamilySet, LineFamily};
use std::path::{Path, PathBuf};
use std::sync::Arc;
use std::time::Instant;

/// What `shapecue report lines-batch` measures.
#[derive(Clone, Debug)]
pub struct LinesBatchOptions {
    /// Meshes to time (default: the full-resolution Stanford bunny of the
    /// shared data, else spot bundled with the repository).
    pub meshes: Vec<PathBuf>,
    /// Views of each given mesh (Fibonacci cameras).
    pub views: usize,
    /// Faces of the generated torus (0: none).
    pub generated_faces: usize,
    /// Views of the generated mesh.
    pub generated_views: usize,
    /// Image size the views frame.
    pub size: [u32; 2],
}

impl Default for LinesBatchOptions {
    fn default() -> Self {
        LinesBatchOptions {
            meshes: Vec::new(),
            views: 32,
            generated_faces: 1_000_000,
            generated_views: 4,
            size: [800, 600],
        }
    }
}

/// The meshes of the report when none is given.
pub fn default_meshes() -> Vec<PathBuf> {
    let bunny = super::shared_data().join("meshes/stanford-bunny.obj");
    if bunny.exists() {
        return vec![bunny];
    }
    vec![Path::new(env!("CARGO_MANIFEST_DIR")).join("data/spot.obj")]
}

/// One timed run of many views.
struct Timed {
    /// Wall ms of the pose part (every pose pass, once).
    pose_ms: f64,
    /// Wall ms from one view's NPZ done to the next's, after the first:
    /// the rate views come out with every file written (at least the view's
    /// own NPZ ms).
    view_ms: Vec<f64>,
    /// Each view's device ms: the kernel time of its passes.
    device_ms: Vec<f64>,
    /// Each view's host ms in the executor: its passes' wall time (line
    /// kernels waited for, visibility plan and rounds, chains, SVG) less
    /// its device ms.
    host_ms: Vec<f64>,
    /// The NPZ on the writer thread (the pieces' arrays with their
    /// provenance, and the file), beside the next view.
    npz_ms: Vec<f64>,
    /// Pieces per view (mean).
    pieces: f64,
}

/// Measures the report.
///
/// # Errors
/// A mesh that cannot be loaded, device failures, or the scratch folder.
pub fn report(gpu: &Arc<Gpu>, o: &LinesBatchOptions) -> Result<Report> {
    let mut r = Report::new("lines-batch", gpu.info.name.clone());
    r.text(format!(
        "Views per second of `shapecue lines MESH --views N --out DIR --npz`: one run per mesh \
         and family set, Fibonacci cameras at {}x{}, exact visibility, an SVG and the segment \
         pieces as NPZ written per view, as the command writes them: on a writer thread beside \
         the next view. Pose: wall ms of the passes that run once (one-rings, normals, \
         curvature and its derivative, the feature size, the BVH). Per view: median wall ms \
         from one view's files done to the next's, over the views after the first (views/s \
         from it); of a \
         view's passes, the device ms (kernel time) and the host ms (their wall time less the \
         kernels: the visibility plan and rounds, chains, the SVG); and the NPZ on the writer \
         thread (the pieces' arrays with their faces and barycentric coordinates, and the \
         file). The kernels are built before any timing. rtsc 1.6 draws a view of the bunny with \
         every family in about 0.2 s on one core.\n",
        o.size[0], o.size[1]
    ));
    let mut t = Table::new(
        "views",
        vec![
            Column::new("mesh", "mesh"),
            Column::new("faces", "faces"),
            Column::new("families", "families"),
            Column::new("views", "views"),
            Column::new("pose ms", "pose_ms"),
            Column::new("per view ms", "per_view_ms"),
            Column::new("device ms", "device_ms"),
            Column::new("host ms", "host_ms"),
            Column::new("NPZ ms (writer)", "npz_ms"),
            Column::new("views/s", "views_per_second"),
            Column::new("pieces per view", "pieces_per_view"),
        ],
    );
    let mut meshes: Vec<(String, Arc<Mesh>, usize)> = Vec::new();
    let paths = match o.meshes.is_empty() {
        true => default_meshes(),
        false => o.meshes.clone(),
    };
    for p in &paths {
        let m = mesh::load(p, &Default::default())?;
        let name = p
            .file_name()
            .map_or_else(String::new, |n| n.to_string_lossy().into());
        meshes.push((name, Arc::new(m), o.views));
    }
    if o.generated_faces > 0 {
        let m = generated_torus(o.generated_faces);
        let name = format!("generated torus ({} faces)", m.n_faces());
        meshes.push((name, Arc::new(m), o.generated_views));
    }
    // Each family set's programs are built once, before any timing.
    let small = Arc::new(mesh::icosphere(1.0, 2));
    for (_, fams) in families() {
        measure(gpu, &small, fams, 2, o.size)?;
    }
    let mut series: Vec<(String, Vec<f64>)> = (families().iter())
        .map(|(label, _)| (label.to_string(), Vec::new()))
        .collect();
    for (name, m, views) in &meshes {
        for (k, (label, fams)) in families().into_iter().enumerate() {
            let timed = measure(gpu, m, fams, *views, o.size)?;
            let (row, vps) = row(name, m, label, *views, timed);
            t.rows.push(row);
            series[k].1.push(vps);
        }
    }
    r.blocks.push(Block::Table(t));
    r.charts.push(Chart::Bars {
        title: "Views per second after the first (SVG and NPZ written)".into(),
        y_label: "views/s".into(),
        log_y: true,
        groups: meshes.iter().map(|m| m.0.clone()).collect(),
        series,
    });
    Ok(r)
}

/// The two family sets timed.
fn families() -> [(&'static str, FamilySet); 2] {
    [
        ("every family", FamilySet::of(&LineFamily::ALL)),
        (
            "contours + suggestive",
            FamilySet::of(&[LineFamily::Contours, LineFamily::Suggestive]),
        ),
    ]
}

/// A torus of about `faces` faces (two per grid cell, 2:1 around).
fn generated_torus(faces: usize) -> Mesh {
    let nv = ((faces as f64 / 4.0).sqrt().round() as usize).max(3);
    mesh::torus(1.0, 0.4, 2 * nv, nv)
}

/// One row of the table, and its views per second.
fn row(name: &str, m: &Mesh, label: &str, views: usize, mut t: Timed) -> (Row, f64) {
    let per_view = median(&mut t.view_ms);
    let npz = median(&mut t.npz_ms);
    let device = median(&mut t.device_ms);
    let host = median(&mut t.host_ms);
    let vps = if per_view > 0.0 { 1e3 / per_view } else { 0.0 };
    let row = Row::new(vec![
        Cell::text(name),
        Cell::int(m.n_faces() as u64),
        Cell::text(label),
        Cell::int(views as u64),
        Cell::num(t.pose_ms, format!("{:.1}", t.pose_ms)),
        Cell::num(per_view, format!("{per_view:.1}")),
        Cell::num(device, format!("{device:.1}")),
        Cell::num(host, format!("{host:.1}")),
        Cell::num(npz, format!("{npz:.1}")),
        Cell::num(vps, format!("{vps:.1}")),
        Cell::num(t.pieces, format!("{:.0}", t.pieces)),
    ]);
    (row, vps)
}

/// Runs `views` Fibonacci views of `m` with `fams` as the command does,
/// writing into a scratch folder removed afterwards.
fn measure(
    gpu: &Arc<Gpu>,
    m: &Arc<Mesh>,
    fams: FamilySet,
    views: usize,
    size: [u32; 2],
) -> Result<Timed> {
    let mut opts = LinesPictureOptions {
        image: false,
        svg: true,
        ..Default::default()
    };
    opts.shot.size = size;
    opts.lines = opts.lines.with_families(fams);
    let cams = fibonacci_views(views, CameraDefaults::default())?;
    let dir = scratch_dir()?;
    let mut scene = lines_views_scene(m.clone(), &opts, cams);
    scene.out_dir = dir.clone();
    scene.prefix = "view".into();
    let exec = ExecOptions {
        force: true,
        ..Default::default()
    };
    let mut device_ms = vec![0.0; views];
    // The NPZ on a writer thread beside the next view, as the command
    // writes it: its ms per view, the pieces written, and when each view's
    // file was done.
    let write = |w: &mut Written, (view, vis): (usize, VisibleLines)| {
        let t = Instant::now();
        let a = segment_arrays(&vis, m);
        w.pieces += a.a.len();
        crate::export::npz::write_segments(&dir.join(format!("view_{view:04}.npz")), &a)?;
        w.npz_ms.push(t.elapsed().as_secs_f64() * 1e3);
        w.done.push(Instant::now());
        Ok(())
    };
    let (run, written) = with_consumer(Written::default(), write, |each| {
        lines_on(gpu, &scene, LineFiles::Folder(&exec), &mut |v| {
            device_ms[v.view] = (v.passes.iter())
                .filter(|p| p.lifetime == Lifetime::View && p.is_kernel())
                .map(|p| p.timing.kernel_ms)
                .sum();
            match v.visible {
                Some(vis) => each((v.view, vis)),
                None => Ok(()),
            }
        })
    });
    let _ = std::fs::remove_dir_all(&dir);
    let rep = run?;
    let laps = rep.timing.laps("view_wall");
    let first = 1.min(laps.len().saturating_sub(1));
    // From one view's file done to the next's: each at least that view's
    // NPZ, which starts after the view before it is done.
    let view_ms: Vec<f64> = (written.done.windows(2))
        .map(|w| (w[1] - w[0]).as_secs_f64() * 1e3)
        .collect();
    let host_ms = (laps.iter().zip(&device_ms))
        .skip(first)
        .map(|(w, d)| w - d)
        .collect();
    Ok(Timed {
        pose_ms: rep.timing.phase_ms("pose_wall"),
        view_ms,
        device_ms: device_ms[first.min(views)..].to_vec(),
        host_ms,
        npz_ms: written.npz_ms[first.min(written.npz_ms.len())..].to_vec(),
        pieces: written.pieces as f64 / views.max(1) as f64,
    })
}

/// What the writer thread of [`measure`] keeps.
#[derive(Default)]
struct Written {
    /// Each view's NPZ ms, in view order.
    npz_ms: Vec<f64>,
    /// Pieces written over all views.
    pieces: usize,
    /// When each view's file was done.
    done: Vec<Instant>,
}

/// A fresh scratch folder of this process.
fn scratch_dir() -> Result<PathBuf> {
    use std::sync::atomic::{AtomicUsize, Ordering};
    static N: AtomicUsize = AtomicUsize::new(0);
    let dir = std::env::temp_dir().join(format!(
        "shapecue-lines-batch-{}-{}",
        std::process::id(),
        N.fetch_add(1, Ordering::Relaxed)
    ));
    std::fs::create_dir_all(&dir).map_err(|source| Error::Io {
        path: dir.clone(),
        source,
    })?;
    Ok(dir)
}
