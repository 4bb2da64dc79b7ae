//! `shapecue report visibility`: exact, object-space visibility of line
//! segments ([`crate::stages::visibility`]) against its f64 brute-force
//! reference ([`crate::cpu::visibility::classify_reference`]), with the
//! depth-buffer method ([`crate::render::depth_visibility`]) beside it, and what
//! each costs in time per view.
//!
//! Per mesh (default: spot bundled with the repository, the full Stanford
//! bunny and the middle frame of BrainStem's first clip from the shared
//! data, skipped with a line of text where absent) and per view (two
//! perspective, one orthographic, fitted to the mesh) with its line
//! families (the bunny: every family; the others: contours, suggestive
//! contours, ridges, valleys and apparent ridges): the segments, the share
//! of line length each method agrees with the reference on (the reference
//! on a deterministic subset of the segments, [`line_agreement::reference_subset`]),
//! and the median wall ms of the exact classification, of the depth-buffer
//! method and of the view's line kernels. The tests of exact visibility
//! (`tests/visibility_meshes.rs`) measure the same meshes, views and
//! families with the same pieces ([`MeshLines`], [`middle_frame`],
//! [`line_agreement`]).

use super::line_agreement::{self as la, f32_positions, fitted_camera, pick};
use super::metrics::median;
use super::{Block, Cell, Chart, Column, Report, Row, Table};
use crate::api::LineSetup;
use crate::cpu::skinning::skin_lbs;
use crate::cpu::visibility::classify_reference;
use crate::error::{Error, Result};
use crate::gpu::Gpu;
use crate::mesh::skinned::{SkinnedMesh, load_gltf};
use crate::mesh::{self, Mesh, topology::vertex_normals};
use crate::render::depth_visibility::{DEFAULT_BIAS, segment_lines, visible_joined};
use crate::render::{Camera, Renderer};
use crate::spec::curvature::CurvatureOptions;
use crate::spec::feature_lines::{FamilySet, LineFamily, Segment};
use crate::spec::view::View;
use crate::spec::visibility::{Pieces, VisibilityOptions};
use crate::spec::visibility_plan::RayPlan;
use crate::stages::bvh::Bvh;
use crate::stages::curvature::CurvatureEstimator;
use crate::stages::feature_lines::{LineExtractor, LineOptions};
use crate::stages::visibility::classify;
use glam::Vec3;
use std::path::{Path, PathBuf};
use std::sync::Arc;
use std::time::Instant;

/// The families measured on every mesh but the bunny.
pub const NAMED: [LineFamily; 5] = [
    LineFamily::Contours,
    LineFamily::Suggestive,
    LineFamily::Ridges,
    LineFamily::Valleys,
    LineFamily::ApparentRidges,
];

/// The views of each mesh: name, direction from the mesh towards the eye,
/// orthographic.
pub const VIEWS: [(&str, [f32; 3], bool); 3] = [
    ("perspective (1, 0.6, 0.8)", [1.0, 0.6, 0.8], false),
    ("perspective (-0.8, 0.3, -0.6)", [-0.8, 0.3, -0.6], false),
    ("orthographic (0.2, 0.5, 1)", [0.2, 0.5, 1.0], true),
];

/// Most ray–face tests of the reference per view by default (about 2 s in
/// f64 on one core).
pub const REFERENCE_TESTS: f64 = 2e8;

/// What `shapecue report visibility` measures.
#[derive(Clone, Debug)]
pub struct VisibilityReportOptions {
    /// Meshes (OBJ, PLY, OFF, STL; a glTF model: the middle frame of its
    /// first clip); empty: [`default_sources`].
    pub meshes: Vec<PathBuf>,
    /// Every line family on the given meshes (else [`NAMED`]).
    pub every_family: bool,
    /// Timed runs per view (medians).
    pub runs: usize,
    /// Image size the views frame, and the depth buffer's.
    pub size: [u32; 2],
    /// Most ray–face tests of the reference per view.
    pub reference_tests: f64,
}

impl Default for VisibilityReportOptions {
    fn default() -> Self {
        VisibilityReportOptions {
            meshes: Vec::new(),
            every_family: false,
            runs: 5,
            size: [480, 360],
            reference_tests: REFERENCE_TESTS,
        }
    }
}

/// A mesh of the report: its name, its file and its line families.
#[derive(Clone, Debug)]
pub struct Source {
    /// As the table names it.
    pub name: String,
    /// Its file (a glTF model: posed by [`middle_frame`]).
    pub path: PathBuf,
    /// The line families measured on it.
    pub families: Vec<LineFamily>,
}

/// The meshes of the report when none is given: spot (bundled), the
/// Stanford bunny with every family and BrainStem's middle frame (shared
/// data; [`super::shared_data`]).
pub fn default_sources() -> Vec<Source> {
    let shared = super::shared_data();
    let source = |name: &str, path: PathBuf, families: &[LineFamily]| Source {
        name: name.into(),
        path,
        families: families.to_vec(),
    };
    vec![
        source(
            "spot",
            Path::new(env!("CARGO_MANIFEST_DIR")).join("data/spot.obj"),
            &NAMED,
        ),
        source(
            "bunny",
            shared.join("meshes/stanford-bunny.obj"),
            &LineFamily::ALL,
        ),
        source(
            "BrainStem",
            shared.join("animations/gltf/BrainStem.glb"),
            &NAMED,
        ),
    ]
}

/// The report's meshes: `o.meshes` named by their file names, else
/// [`default_sources`].
pub fn sources(o: &VisibilityReportOptions) -> Vec<Source> {
    if o.meshes.is_empty() {
        return default_sources();
    }
    let families: &[LineFamily] = if o.every_family {
        &LineFamily::ALL
    } else {
        &NAMED
    };
    (o.meshes.iter())
        .map(|p| Source {
            name: p
                .file_name()
                .map_or_else(|| p.display().to_string(), |n| n.to_string_lossy().into()),
            path: p.clone(),
            families: families.to_vec(),
        })
        .collect()
}

/// Whether `p` names a glTF model (`.glb`, `.gltf`).
fn is_gltf(p: &Path) -> bool {
    p.extension()
        .and_then(|e| e.to_str())
        .is_some_and(|e| e.eq_ignore_ascii_case("glb") || e.eq_ignore_ascii_case("gltf"))
}

/// The mesh of a file: a glTF model's [`middle_frame`], else the mesh as
/// [`mesh::load`] reads it.
///
/// # Errors
/// A file that cannot be read, or a glTF model without a clip.
pub fn load(p: &Path) -> Result<Mesh> {
    if is_gltf(p) {
        middle_frame(p)
    } else {
        mesh::load(p, &Default::default())
    }
}

/// The middle frame of a skinned glTF model's first clip: welded as the
/// scene executor welds it, skinned (linear blend) by the CPU twin.
///
/// # Errors
/// A file that cannot be read, or a model without an animation clip.
pub fn middle_frame(path: &Path) -> Result<Mesh> {
    let (m, _) = load_gltf(path)?.welded();
    let Some(clip) = m.clips.first() else {
        return Err(Error::input(
            path.display().to_string(),
            "animations",
            "the model has no animation clip to take a frame of",
        ));
    };
    let mats = SkinnedMesh::flatten(&m.joint_matrices(Some(0), 0.5 * clip.duration)?);
    let rest = f32_positions(&m.rest.positions);
    let posed = skin_lbs(&rest, &m.joints, &m.weights, &mats);
    Ok(Mesh {
        positions: posed.iter().map(|q| q.map(f64::from)).collect(),
        faces: m.rest.faces.clone(),
        normals: None,
    })
}

/// The lines of one mesh: the curvature with its derivative once (as
/// [`crate::api::line_segments_on`] runs it, default setup), then the
/// segments of any view.
pub struct MeshLines {
    est: CurvatureEstimator,
    ex: LineExtractor,
    feature_size: f32,
}

impl MeshLines {
    /// The curvature of `m` on `gpu`, and an extractor of its lines.
    ///
    /// # Errors
    /// Device failures, a mesh the estimator refuses.
    pub fn new(gpu: Arc<Gpu>, m: &Mesh) -> Result<MeshLines> {
        let setup = LineSetup::default();
        let copts = CurvatureOptions {
            dcurv: true,
            ..setup.curvature
        };
        let mut est = CurvatureEstimator::new(gpu.clone(), m.n_vertices(), &m.faces, copts)?;
        est.set_positions(&m.positions)?;
        est.run()?;
        let fs = est.feature_size(setup.feature_size, &m.positions, &m.faces)?;
        let ex = LineExtractor::new(gpu, m.n_vertices(), &m.faces)?;
        Ok(MeshLines {
            est,
            ex,
            feature_size: fs as f32,
        })
    }

    /// The segments of `families` seen in `view`, sorted
    /// ([`line_agreement::sort_segments`]), and the line kernels' ms.
    ///
    /// # Errors
    /// Device failures, a view the extraction refuses.
    pub fn of(&mut self, view: View, families: &[LineFamily]) -> Result<(Vec<Segment>, f64)> {
        let opts = LineOptions::default().with_families(FamilySet::of(families));
        let (mut segs, stats) =
            (self.ex).extract_device(&self.est, view, self.feature_size, opts)?;
        la::sort_segments(&mut segs);
        Ok((segs, stats.timing.kernel_ms))
    }
}

/// What one view measured.
struct Measured {
    segments: usize,
    checked: usize,
    hidden: f64,
    exact: f64,
    exact_ms: f64,
    overflows: u32,
    /// Agreement and ms of the depth-buffer method (`None`: no OpenGL).
    depth: Option<(f64, f64)>,
    lines_ms: f64,
    reference_ms: f64,
}

/// What the views of one mesh share.
struct MeshRun<'a> {
    m: &'a Mesh,
    p: Vec<[f32; 3]>,
    normals: Vec<[f32; 3]>,
    lines: MeshLines,
    bvh: Bvh,
    families: &'a [LineFamily],
}

/// Measures the report.
///
/// # Errors
/// A given mesh that cannot be loaded, device or OpenGL failures (a
/// machine without headless OpenGL leaves the depth-buffer cells saying
/// so).
pub fn report(gpu: &Arc<Gpu>, o: &VisibilityReportOptions) -> Result<Report> {
    let mut r = Report::new("visibility", gpu.info.name.clone());
    let mut renderer = match la::depth_renderer(o.size[0], o.size[1]) {
        Ok(x) => Some(x),
        Err(Error::NoGl { .. }) => None,
        Err(e) => return Err(e),
    };
    let mut notes = Vec::new();
    if renderer.is_none() {
        notes.push("This machine has no headless OpenGL: the depth-buffer cells say so.".into());
    }
    let mut meshes = Table::new(
        "meshes",
        vec![
            Column::new("mesh", "mesh"),
            Column::new("faces", "faces"),
            Column::new("line families", "families"),
            Column::new("BVH build ms", "bvh_build_ms"),
        ],
    );
    let mut views = Table::new("views", view_columns());
    let mut points = Vec::new();
    let mut bars = Bars::default();
    let given = !o.meshes.is_empty();
    for s in sources(o) {
        if !given && !s.path.exists() {
            notes.push(format!(
                "{}: skipped, {} not found (the shared data sets are looked for in \
                 $SHAPECUE_SHARED_DATA, else ../shared/data).",
                s.name,
                s.path.display()
            ));
            continue;
        }
        let m = load(&s.path)?;
        let mut run = MeshRun::new(gpu, &m, &s.families)?;
        meshes.rows.push(mesh_row(&s, &m, run.build()?));
        for (k, (vname, dir, ortho)) in VIEWS.into_iter().enumerate() {
            let cam = fitted_camera(&m, Vec3::from(dir), ortho, aspect(o.size))?;
            let v = run.view(&cam, renderer.as_mut(), o)?;
            let short = format!("{} {}", s.name, ["p1", "p2", "o"][k]);
            points.push((format!("{short} exact"), v.exact_ms, 1.0 - v.exact));
            if let Some((agree, ms)) = v.depth {
                points.push((format!("{short} depth"), ms, 1.0 - agree));
            }
            bars.push(short, &v);
            views.rows.push(view_row(&s.name, vname, &v));
        }
    }
    r.text(methods_text());
    if !notes.is_empty() {
        r.text(notes.join("\n") + "\n");
    }
    r.blocks.push(Block::Table(meshes));
    r.text(views_text(o));
    r.blocks.push(Block::Table(views));
    r.charts.push(Chart::Scatter {
        title: "Disagreement with the f64 reference against time, per view".into(),
        x_label: "wall ms per view".into(),
        y_label: "share of line length in disagreement".into(),
        points,
    });
    r.charts.push(bars.chart());
    Ok(r)
}

/// The bars of the ms per view: exact, depth buffer (0 without OpenGL),
/// line kernels.
#[derive(Default)]
struct Bars {
    groups: Vec<String>,
    ms: [Vec<f64>; 3],
}

impl Bars {
    fn push(&mut self, group: String, v: &Measured) {
        self.groups.push(group);
        let depth = v.depth.map_or(0.0, |d| d.1);
        for (s, x) in self.ms.iter_mut().zip([v.exact_ms, depth, v.lines_ms]) {
            s.push(x);
        }
    }

    fn chart(self) -> Chart {
        let names = ["exact", "depth buffer", "line kernels"];
        Chart::Bars {
            title: "Wall ms per view of each visibility method, and the line kernels' ms".into(),
            y_label: "ms".into(),
            log_y: true,
            groups: self.groups,
            series: names.iter().map(|n| n.to_string()).zip(self.ms).collect(),
        }
    }
}

fn aspect(size: [u32; 2]) -> f32 {
    size[0] as f32 / size[1].max(1) as f32
}

/// The report's opening text: the methods, and the meshes' table.
fn methods_text() -> String {
    "Exact visibility of line segments (`shapecue lines --visibility exact`: in object \
     space, rays from the eye through the mesh's BVH at samples along each segment, then \
     bisection where neighbouring samples differ) and the depth-buffer method (`--visibility \
     depth`: the mesh drawn, each line tested against its depth), each against the f64 \
     brute-force reference of exact visibility (every face per ray, at the same samples and \
     bisection steps). Per mesh: its line families and the wall ms of building its BVH on \
     the device, once for every view.\n"
        .to_string()
}

/// The text before the views' table.
fn views_text(o: &VisibilityReportOptions) -> String {
    let n = o.runs.max(1);
    format!(
        "\nPer view at {}x{}: the segments of the mesh's line families, those checked \
         against the reference (every k-th, k the least that keeps within {:.0e} ray–face \
         tests per view), the hidden share of the line length, and the share of the checked \
         length on which each method agrees with the reference (the depth-buffer method read \
         at {} points per segment). Median wall ms of {n} run{}: exact ms classifies every \
         segment of the view on the device (plan, rounds and transfers), depth buffer ms \
         draws the mesh, reads its depth back and tests every segment; line kernels ms is the \
         kernel time of the view's line extraction (the curvature, shared by the views, \
         apart). The plot draws disagreement against ms on log axes (a method in full \
         agreement on a view has no point there), then the ms per view as bars.\n",
        o.size[0],
        o.size[1],
        o.reference_tests,
        la::DEPTH_POINTS,
        if n == 1 { "" } else { "s" },
    )
}

fn view_columns() -> Vec<Column> {
    vec![
        Column::new("mesh", "mesh"),
        Column::new("view", "view"),
        Column::new("segments", "segments"),
        Column::new("checked", "checked_segments"),
        Column::new("hidden %", "hidden_percent"),
        Column::new("exact agrees %", "exact_agreement_percent"),
        Column::new("exact ms", "exact_ms"),
        Column::new("depth buffer agrees %", "depth_agreement_percent"),
        Column::new("depth buffer ms", "depth_ms"),
        Column::new("line kernels ms", "line_kernels_ms"),
        Column::hidden("reference_ms"),
        Column::hidden("stack_overflows"),
    ]
}

fn mesh_row(s: &Source, m: &Mesh, build_ms: f64) -> Row {
    let fams = if s.families.len() == LineFamily::ALL.len() {
        "every family".to_string()
    } else {
        let names: Vec<&str> = s.families.iter().map(|f| f.name()).collect();
        names.join(", ")
    };
    Row::new(vec![
        Cell::text(&s.name),
        Cell::int(m.n_faces() as u64),
        Cell::text(fams),
        Cell::num(build_ms, format!("{build_ms:.1}")),
    ])
}

fn view_row(mesh: &str, view: &str, v: &Measured) -> Row {
    // Rounded down: a share short of full agreement never prints as 100.
    let pct = |x: f64| Cell::num(100.0 * x, format!("{:.4}", (1e6 * x).floor() / 1e4));
    let ms = |x: f64| Cell::num(x, format!("{x:.1}"));
    let gl = || Cell::shown("no OpenGL", serde_json::Value::Null);
    Row::new(vec![
        Cell::text(mesh),
        Cell::text(view),
        Cell::int(v.segments as u64),
        Cell::int(v.checked as u64),
        Cell::num(100.0 * v.hidden, format!("{:.2}", 100.0 * v.hidden)),
        pct(v.exact),
        ms(v.exact_ms),
        v.depth.map_or_else(gl, |d| pct(d.0)),
        v.depth.map_or_else(gl, |d| ms(d.1)),
        ms(v.lines_ms),
        ms(v.reference_ms),
        Cell::int(v.overflows),
    ])
}

/// Wall ms since `t0`.
fn ms(t0: Instant) -> f64 {
    t0.elapsed().as_secs_f64() * 1e3
}

impl<'a> MeshRun<'a> {
    fn new(gpu: &Arc<Gpu>, m: &'a Mesh, families: &'a [LineFamily]) -> Result<MeshRun<'a>> {
        let p = f32_positions(&m.positions);
        Ok(MeshRun {
            lines: MeshLines::new(gpu.clone(), m)?,
            bvh: Bvh::new(gpu.clone(), p.len(), &m.faces)?,
            normals: vertex_normals(m),
            p,
            m,
            families,
        })
    }

    /// Builds the tree (twice: the second build's wall ms is returned, the
    /// first pays for the kernels' compilation).
    fn build(&mut self) -> Result<f64> {
        self.bvh.build(&self.p)?;
        let t0 = Instant::now();
        self.bvh.build(&self.p)?;
        Ok(ms(t0))
    }

    /// Measures one view from `cam` (`r`: the depth-buffer method's
    /// renderer, where there is OpenGL).
    fn view(
        &mut self,
        cam: &Camera,
        r: Option<&mut Renderer>,
        o: &VisibilityReportOptions,
    ) -> Result<Measured> {
        let view = cam.view(o.size[0], o.size[1]);
        let runs = o.runs.max(1);
        let (segs, first_ms) = self.lines.of(view, self.families)?;
        let mut lines_ms = vec![first_ms];
        for _ in 1..runs {
            lines_ms.push(self.lines.of(view, self.families)?.1);
        }
        let (dev, exact_ms, overflows) = self.exact(&segs, &view, runs)?;
        let opts = VisibilityOptions::default();
        let plan = RayPlan::new(&self.p, &self.m.faces, &segs, &view, &opts)?;
        let at = la::reference_subset(&plan, self.m.faces.len(), o.reference_tests);
        let t0 = Instant::now();
        let reference = classify_reference(&self.m.positions, &self.m.faces, &plan.subset(&at))?;
        let reference_ms = ms(t0);
        let sub = pick(&segs, &at);
        let depth = match r {
            Some(r) => Some(self.depth(r, cam, &segs, (&sub, &reference), runs)?),
            None => None,
        };
        Ok(Measured {
            segments: segs.len(),
            checked: at.len(),
            hidden: la::hidden_share(&segs, &dev),
            exact: la::share(&sub, &pick(&dev, &at), &reference),
            exact_ms,
            overflows,
            depth,
            lines_ms: median(&mut lines_ms),
            reference_ms,
        })
    }

    /// The device's pieces of `segs`, the median wall ms of `runs`
    /// classifications and their stack overflows.
    fn exact(
        &mut self,
        segs: &[Segment],
        view: &View,
        runs: usize,
    ) -> Result<(Vec<Pieces>, f64, u32)> {
        let opts = VisibilityOptions::default();
        let mut times = Vec::with_capacity(runs);
        let mut first = None;
        for _ in 0..runs {
            let t0 = Instant::now();
            let (pieces, overflows) =
                classify(&mut self.bvh, &self.p, &self.m.faces, segs, view, &opts)?;
            times.push(ms(t0));
            first.get_or_insert((pieces, overflows));
        }
        let (pieces, overflows) = first.unwrap_or_default();
        Ok((pieces, median(&mut times), overflows))
    }

    /// The depth-buffer method from `cam`: its agreement with the
    /// `reference` pieces of the `checked` segments, and the median wall ms
    /// of drawing the mesh and testing every segment of `segs`.
    fn depth(
        &self,
        r: &mut Renderer,
        cam: &Camera,
        segs: &[Segment],
        (checked, reference): (&[Segment], &[Pieces]),
        runs: usize,
    ) -> Result<(f64, f64)> {
        let vp = cam.view_proj(r.aspect());
        let kinds: Vec<u32> = self.families.iter().map(|&f| f as u32).collect();
        let mut times = Vec::with_capacity(runs);
        let mut frame = None;
        for _ in 0..runs {
            let t0 = Instant::now();
            let f = la::depth_frame(r, &self.p, &self.m.faces, &self.normals, cam)?;
            let lines: Vec<_> = (kinds.iter())
                .flat_map(|&k| segment_lines(vp, segs, k, |_| 1.0))
                .collect();
            let visible = visible_joined(&lines, &f, DEFAULT_BIAS);
            times.push(ms(t0));
            std::hint::black_box(visible);
            frame = Some(f);
        }
        let agree = match &frame {
            Some(f) => la::depth_share_in(f, cam, checked, reference),
            None => 1.0,
        };
        Ok((agree, median(&mut times)))
    }
}
