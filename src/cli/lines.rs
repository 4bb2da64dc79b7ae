//! `shapecue lines`: every line family of rtsc (Rusinkiewicz and DeCarlo's
//! real-time suggestive contours program) on one mesh from one camera, by
//! one front-door call ([`shapecue::lines_picture_on`]): a PNG of the lines
//! over the mesh, or an SVG with a group per family, and optionally the 3-D
//! segments (family, strength) as JSON. With `--views N` or `--cameras
//! FILE` and `--out DIR`, many views of the mesh in one run ([`views`]).

mod views;

use super::{check_outputs, write_json};
use anyhow::{Result, bail};
use clap::Args;
use shapecue::LinesPictureOptions;
use shapecue::api::Gpu;
use shapecue::api::{Hidden, LineSetup, VisibilityMethod, VisibleLines};
use shapecue::export::npz::SegmentArrays;
use shapecue::mesh::{LoadOptions, NormalsSource};
use shapecue::spec::curvature::{AccumulateChoice, Compat, CurvatureOptions};
use shapecue::spec::feature_lines::FeatureSize;
use shapecue::spec::feature_lines::{FamilySet, LineFamily, Segment};
use std::path::PathBuf;
use std::sync::Arc;

/// The arguments of `shapecue lines`.
#[derive(Args)]
pub struct LinesArgs {
    /// Input mesh (.obj, .ply, .off), or a generated one: torus, sphere,
    /// ellipsoid, cylinder or plane (with --vertices).
    mesh: String,
    /// Vertices of a generated mesh (about; default 20000).
    #[arg(long)]
    vertices: Option<usize>,
    /// The families, comma-separated: contours, suggestive, ridges, valleys,
    /// apparent-ridges, suggestive-highlights, principal-highlights,
    /// isophotes, k-zero, h-zero, dwkr-zero, boundaries.
    #[arg(long, default_value = "contours,suggestive")]
    lines: String,
    /// Eye position, e.g. 5,5,5 (default: from direction 1,1,1, framed).
    #[arg(long, value_delimiter = ',', allow_negative_numbers = true)]
    eye: Option<Vec<f32>>,
    /// Point looked at (default: the centre of the bounding box).
    #[arg(long, value_delimiter = ',', allow_negative_numbers = true)]
    target: Option<Vec<f32>>,
    /// Up direction (default +Y, or +Z when looking along Y).
    #[arg(long, value_delimiter = ',', allow_negative_numbers = true)]
    up: Option<Vec<f32>>,
    /// Vertical field of view in degrees.
    #[arg(long, default_value_t = 40.0)]
    fov: f32,
    /// Orthographic projection.
    #[arg(long)]
    ortho: bool,
    /// Image size, e.g. 800x600.
    #[arg(long, default_value = "800x600")]
    size: String,
    /// Line width in pixels (default 2, or the image's larger side if less).
    #[arg(long)]
    width: Option<f32>,
    /// Suggestive-contour threshold: D_w κr tanθ above it, times 1 / feature
    /// size squared (rtsc's default). D_w κr = 0 is drawn at this offset, as
    /// rtsc draws it.
    #[arg(long, default_value_t = 0.01)]
    sc_threshold: f32,
    /// Fade of suggestive contours and highlights: strength r / (r + fade)
    /// for a margin r above the threshold, times 1 / feature size squared
    /// (rtsc's default).
    #[arg(long, default_value_t = 0.03)]
    fade: f32,
    /// Ridge and valley threshold (times 1 / feature size).
    #[arg(long, default_value_t = 0.1)]
    rv_threshold: f32,
    /// Apparent-ridge threshold on q1, a squared curvature (times 1 /
    /// feature size squared).
    #[arg(long, default_value_t = 0.1)]
    ar_threshold: f32,
    /// Principal-highlight threshold (times 1 / feature size squared).
    #[arg(long, default_value_t = 0.04)]
    ph_threshold: f32,
    /// Suggestive-highlight threshold (times 1 / feature size squared).
    #[arg(long, default_value_t = 0.02)]
    sh_threshold: f32,
    /// Isophote levels N: n·l = j/N for |j| < N.
    #[arg(long, default_value_t = 20)]
    isophotes: u32,
    /// Direction towards the light (isophotes), e.g. 0,0,1.
    #[arg(long, value_delimiter = ',', allow_negative_numbers = true)]
    light: Option<Vec<f32>>,
    /// The length the thresholds are scaled by: rtsc (rtsc's feature size:
    /// 0.01 over the 10th percentile of |k1| and |k2| at 500 sampled
    /// vertices, at most 5 % of the bounding sphere's radius), edge (the
    /// median edge length), or a length in the mesh's units.
    #[arg(long, default_value = "rtsc")]
    feature_size: String,
    /// Vertex normals the curvature starts from: file (those a mesh file
    /// stores, OBJ vn or PLY nx ny nz, as trimesh2 and rtsc use them; the
    /// faces' where it stores none) or computed (always from the faces).
    #[arg(long, value_parser = super::choice::<NormalsSource>(), default_value = "file")]
    normals: NormalsSource,
    /// Merge vertices at identical positions before computing: for files
    /// that split every face from its neighbours (STL-like triangle soups,
    /// on which no line is found) or along UV and normal seams (drawn as
    /// boundaries otherwise, as rtsc draws them).
    #[arg(long)]
    weld: bool,
    /// Curvature's least squares: trimesh2 2.16's (the curvature rtsc
    /// computes its lines from), or the exact solve (closer to the analytic
    /// lines, but it moves rtsc's on thin triangles and flat patches).
    #[arg(long, value_parser = super::choice::<Compat>(), default_value = "trimesh2")]
    compat: Compat,
    /// Curvature's one-ring accumulation (default: gather, bitwise
    /// reproducible).
    #[arg(long, value_parser = super::choice::<AccumulateChoice>(), default_value = "auto")]
    accumulate: AccumulateChoice,
    /// Keep lines on back faces.
    #[arg(long)]
    no_cull: bool,
    /// rtsc's tests off: every zero crossing (contours without the κr > 0
    /// test, suggestive contours as the κr = 0 loops, highlights and
    /// ridge-like lines without their threshold and extremum checks).
    #[arg(long)]
    no_test: bool,
    /// Full-strength lines (no fading by the test's margin).
    #[arg(long)]
    no_fade: bool,
    /// rtsc's Hermite placement of suggestive contours and highlights (a
    /// cubic through κr sin²θ and its gradient).
    #[arg(long)]
    hermite: bool,
    /// Hermite (cubic) placement of the K = 0 and H = 0 crossings, from the
    /// curvature gradients (shapecue's addition to rtsc).
    #[arg(long)]
    hermite_kh: bool,
    /// How the hidden parts of the SVG and --segments are found: exact (in
    /// object space, by rays towards the eye over a BVH of the mesh; no
    /// OpenGL is needed for SVG and segments) or depth (against the drawn
    /// picture's depth buffer).
    #[arg(long, value_parser = super::choice::<VisibilityMethod>(), default_value = "exact")]
    visibility: VisibilityMethod,
    /// Hidden parts in the SVG: remove, faded or dashed.
    #[arg(long, value_parser = super::choice::<Hidden>(), default_value = "remove")]
    hidden: Hidden,
    /// Output: .png (picture) or .svg (a group per family).
    #[arg(short, long)]
    output: Option<PathBuf>,
    /// Also write the 3-D segments as JSON: with exact visibility, each
    /// drawn segment split where its visibility changes (family, strength,
    /// ends, visible, the faces it lies on, its chain) and the chains;
    /// else every segment (family, strength, ends). With --views or
    /// --cameras, give no file: each view's go next to its SVG.
    #[arg(long, num_args = 0..=1, value_name = "FILE")]
    segments: Option<Option<PathBuf>>,
    /// With --views or --cameras: each view's segment pieces also as NPZ
    /// arrays next to its SVG (a, b, family, strength, visible, faces,
    /// chain, and the face each piece lies in with its ends' barycentric
    /// coordinates; `numpy.load`).
    #[arg(long)]
    npz: bool,
    /// With --views or --cameras: each view's per-vertex fields as NPZ next
    /// to its SVG (n·v, κr sin²θ, D_w κr and q1 as rtsc keeps them, world
    /// units; ndotv, kr, dwkr, q1).
    #[arg(long)]
    fields: bool,
    /// Many views in one run: N views fitted to the mesh from directions
    /// spread evenly over the sphere (the Fibonacci lattice), an SVG each
    /// in --out.
    #[arg(long, value_name = "N")]
    views: Option<usize>,
    /// Many views in one run: the cameras of a JSON file
    /// ({"cameras": [{"eye": [x,y,z], "target": [x,y,z]}, ...]}, with
    /// optional "up", "fov" and "ortho" height), an SVG each in --out.
    #[arg(long, value_name = "FILE.json")]
    cameras: Option<PathBuf>,
    /// The folder of --views or --cameras: an SVG per view (and a PNG with
    /// --png, segments with --segments), the run's report and manifest.json.
    #[arg(long, value_name = "DIR")]
    out: Option<PathBuf>,
    /// With --views or --cameras: also a PNG per view (needs OpenGL).
    #[arg(long)]
    png: bool,
    /// With --views or --cameras: print the plan (the passes, per pose or
    /// per view, and how often each runs) and the files, and run nothing.
    #[arg(long)]
    explain: bool,
    /// Overwrite existing output files. With --out, the files of the
    /// earlier run that manifest.json lists and this run does not write are
    /// removed, so that the folder holds one run.
    #[arg(long)]
    force: bool,
    /// With --out: continue an interrupted or failed run. Each view whose
    /// files match manifest.json is kept, the others are computed; refused
    /// if the mesh, the cameras or an option changed.
    #[arg(long)]
    resume: bool,
}

/// What the two ways of `shapecue lines` share, checked: the image size,
/// the families, the line width, the feature size and where the mesh comes
/// from.
struct Common {
    size: (u32, u32),
    fams: FamilySet,
    width: f32,
    feature_size: FeatureSize,
    path: PathBuf,
    /// A generated mesh's vertex count (`None`: a file).
    generated: Option<usize>,
    /// Keep or drop the normals the file stores.
    normals: NormalsSource,
    /// Merge vertices at identical positions.
    weld: bool,
}

/// The checks of both ways of `shapecue lines`.
fn common(a: &LinesArgs) -> Result<Common> {
    let (w, h) = super::size_arg(&a.size)?;
    let fams = FamilySet::parse(&a.lines)?;
    if fams == FamilySet::NONE {
        bail!("--lines names no family");
    }
    let width = a.width.unwrap_or(2.0f32.min(w.max(h) as f32));
    super::width_arg(width, (w, h), "line")?;
    if fams.has(LineFamily::Isophotes) && a.isophotes == 0 {
        bail!("--isophotes 0: isophotes need at least 1 level");
    }
    let feature_size: FeatureSize = a.feature_size.parse()?;
    let path = PathBuf::from(&a.mesh);
    let generated = !path.exists() && shapecue::mesh::generated_by_name(&a.mesh, 4).is_some();
    if !generated && a.vertices.is_some() {
        bail!(
            "--vertices is for generated meshes (torus, sphere, ellipsoid, cylinder, plane); {} is a file",
            a.mesh
        );
    }
    let vertices = a.vertices.unwrap_or(20_000);
    if generated {
        shapecue::spec::limits::check_mesh_vertices("--vertices", vertices)?;
    }
    Ok(Common {
        size: (w, h),
        fams,
        width,
        feature_size,
        path,
        generated: generated.then_some(vertices),
        normals: a.normals,
        weld: a.weld,
    })
}

impl Common {
    /// The files the run reads (none for a generated mesh).
    fn inputs(&self) -> Vec<&std::path::Path> {
        match self.generated {
            Some(_) => vec![],
            None => vec![self.path.as_path()],
        }
    }

    /// The mesh, loaded or generated.
    fn mesh(&self, name: &str) -> Result<shapecue::Mesh> {
        Ok(match self.generated {
            Some(n) => {
                (shapecue::mesh::generated_by_name(name, n))
                    .expect("checked by common")
                    .1
            }
            None => {
                let opts = LoadOptions {
                    normals: self.normals,
                    weld: self.weld,
                };
                let m = shapecue::mesh::load(&self.path, &opts)?;
                if let Some(w) = m.soup_warning(&self.path.display().to_string()) {
                    eprintln!("warning: {w}");
                }
                m
            }
        })
    }
}

/// Runs `shapecue lines`.
pub fn run(device: Option<&str>, a: LinesArgs) -> Result<()> {
    if a.views.is_some() || a.cameras.is_some() || a.out.is_some() {
        return views::run(device, a);
    }
    for (on, flag) in [
        (a.png, "--png"),
        (a.explain, "--explain"),
        (a.npz, "--npz"),
        (a.fields, "--fields"),
        (a.resume, "--resume"),
    ] {
        if on {
            bail!("{flag} goes with --views N or --cameras FILE (and --out DIR)");
        }
    }
    let Some(output) = a.output.clone() else {
        bail!(
            "give -o FILE.svg or -o FILE.png for one picture, or --views N or --cameras \
             FILE.json with --out DIR for many views"
        );
    };
    let segments = match &a.segments {
        Some(None) => bail!("--segments FILE: give the file the segments go to"),
        Some(Some(p)) => Some(p.clone()),
        None => None,
    };
    let c = common(&a)?;
    let (w, h) = c.size;
    let svg = super::png_or_svg("--output", &output, "a group per family")?;
    if !svg && a.hidden != Hidden::Remove {
        bail!(
            "--hidden {}: hidden parts are drawn in SVG output only; a PNG shows the visible lines",
            a.hidden.name()
        );
    }
    let outputs: Vec<&std::path::Path> = std::iter::once(output.as_path())
        .chain(segments.as_deref())
        .collect();
    check_outputs(c.inputs(), outputs, a.force)?;
    let mesh = c.mesh(&a.mesh)?;
    let mut opts = picture_options(&a, &c)?;
    opts.image = !svg;
    opts.svg = svg;
    // The segments' visibility is planned for them, with or without an SVG.
    opts.pieces = segments.is_some();
    let gpu = Arc::new(Gpu::new(device)?);
    let pic = shapecue::lines_picture_on(&gpu, &mesh, &opts)?;
    match (&pic.layers, &pic.frame) {
        (Some(layers), _) if svg => shapecue::export::svg::write_svg_layers(&output, layers, w, h)?,
        (_, Some(frame)) => frame.save_png(&output)?,
        _ => bail!("the picture drew no image for {}", output.display()),
    }
    if let Some(p) = &segments {
        let arrays = (pic.visible.as_ref()).map(|v| (v, shapecue::api::segment_arrays(v, &mesh)));
        let visible = arrays.as_ref().map(|(v, a)| (*v, a));
        let doc = segments_doc(visible, &pic.segments, pic.feature_size);
        write_json(p, &doc)?;
    }
    let found = summary(&pic.segments);
    super::print(format_args!(
        "{}: {found}, {}, kernels {:.2} ms",
        output.display(),
        normals_used(&mesh),
        pic.timing.kernel_ms
    ))?;
    Ok(())
}

/// The picture's options from the arguments (checked by [`common`]); the
/// caller sets `image` and `svg`.
fn picture_options(a: &LinesArgs, c: &Common) -> Result<LinesPictureOptions> {
    let (w, h) = c.size;
    let fams = c.fams;
    let mut opts = LinesPictureOptions {
        shot: super::shot_arg([&a.eye, &a.target, &a.up], a.fov, a.ortho, [w, h])?,
        line_width: c.width,
        hidden: a.hidden,
        visibility: a.visibility,
        setup: LineSetup {
            curvature: CurvatureOptions {
                accumulate: a.accumulate.resolve(),
                compat: a.compat,
                ..Default::default()
            },
            feature_size: c.feature_size,
        },
        ..Default::default()
    };
    opts.lines = opts.lines.with_families(fams);
    let l = &mut opts.lines;
    l.threshold = a.sc_threshold;
    l.fade = a.fade;
    let c = &mut l.curves;
    c.ridge_threshold = a.rv_threshold;
    c.apparent_threshold = a.ar_threshold;
    c.principal_threshold = a.ph_threshold;
    c.highlight_threshold = a.sh_threshold;
    c.isophotes = a.isophotes;
    if let Some(l) = super::vec3_arg(&a.light, "light")? {
        c.light = l.to_array();
    }
    c.cull = !a.no_cull;
    c.test = !a.no_test;
    c.fade = !a.no_fade;
    c.hermite = a.hermite;
    c.hermite_kh = a.hermite_kh;
    Ok(opts)
}

/// The segments document of `--segments` (one picture's, or one view's):
/// with exact visibility (`visible`, with its pieces as the NPZ arrays hold
/// them: [`shapecue::api::segment_arrays`], their faces and barycentric
/// coordinates included) the drawn segments split into their pieces and
/// the chains, else every segment; with the feature size.
fn segments_doc(
    visible: Option<(&VisibleLines, &SegmentArrays)>,
    segments: &[Segment],
    feature_size: f32,
) -> serde_json::Value {
    let family = |k: u32| LineFamily::from_kind(k).map_or("unknown", |f| f.name());
    match visible {
        Some((v, arr)) => {
            let pieces: Vec<serde_json::Value> = (v.chain_pieces.iter().enumerate())
                .map(|(i, p)| {
                    let s = &v.segments[p.seg as usize];
                    let face = (arr.face[i] >= 0).then_some(arr.face[i]);
                    serde_json::json!({
                        "family": family(s.family),
                        "strength": s.strength,
                        "a": arr.a[i],
                        "b": arr.b[i],
                        "visible": p.visible,
                        "faces": v.faces[p.seg as usize].as_slice(),
                        "chain": arr.chain[i],
                        "face": face,
                        "bary": face.map(|_| arr.bary[i]),
                    })
                })
                .collect();
            let chains: Vec<serde_json::Value> = (v.chains.iter())
                .map(|c| {
                    let idx: Vec<u32> = c.pieces.iter().map(|p| p.0).collect();
                    serde_json::json!({"family": family(c.layer), "visible": c.visible, "segments": idx})
                })
                .collect();
            serde_json::json!({
                "feature_size": feature_size,
                "visibility": "exact",
                "segments": pieces,
                "chains": chains,
                "mean_visible_chain_segments": v.mean_chain_length(),
            })
        }
        None => {
            let segs: Vec<serde_json::Value> = (segments.iter())
                .map(|s| serde_json::json!({"family": family(s.family), "strength": s.strength, "a": s.a, "b": s.b}))
                .collect();
            serde_json::json!({"feature_size": feature_size, "segments": segs})
        }
    }
}

/// What the run found, in words: the segments per family.
/// Which normals the curvature started from, as the run's summary says it.
fn normals_used(mesh: &shapecue::Mesh) -> String {
    if mesh.normals.is_none() {
        return "normals from the faces".into();
    }
    match mesh.normals_against_faces() {
        0 => "normals from the file".into(),
        n => format!("normals from the file ({n} point against the faces' orientation)"),
    }
}

fn summary(segments: &[Segment]) -> String {
    let mut counts = std::collections::BTreeMap::<&str, usize>::new();
    for s in segments {
        if let Some(f) = LineFamily::from_kind(s.family) {
            *counts.entry(f.name()).or_default() += 1;
        }
    }
    let list: Vec<String> = counts.iter().map(|(k, v)| format!("{k} {v}")).collect();
    match segments.len() {
        0 => "no segments: no line of the chosen families is in view".to_string(),
        1 => format!("1 segment ({})", list.join(", ")),
        n => format!("{n} segments ({})", list.join(", ")),
    }
}
