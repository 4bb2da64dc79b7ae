//! `shapecue lines MESH --views N --out DIR` and `--cameras FILE.json`:
//! many views of one mesh in one run of the scene executor (the pose passes
//! once, the view passes per camera). Per view an SVG (exact visibility
//! needs no OpenGL), with `--png` a PNG, with `--segments` the segments
//! document of `shapecue lines --segments`; then `manifest.json`: the mesh,
//! the options, each view's camera and files, and the run's timing.

mod manifest;

use super::{LinesArgs, check_outputs, common, picture_options, segments_doc};
use anyhow::{Result, bail};
use serde_json::{Value, json};
use shapecue::api::{
    CameraDefaults, ExecOptions, Gpu, LineFiles, LineView, MAX_VIEWS, RunReport, fibonacci_views,
    lines_on, lines_views_scene, load_camera_file, output_paths, with_consumer,
};
use std::path::{Path, PathBuf};
use std::sync::Arc;
use std::time::Instant;

/// The files of a views run, before it starts.
struct Files {
    /// Each view's images (PNG, SVG) in view order.
    images: Vec<(usize, PathBuf)>,
    /// The executor's report.
    report: PathBuf,
    /// Each view's segments document, where asked.
    segments: Option<Vec<PathBuf>>,
    /// Each view's segment arrays (NPZ), where asked.
    npz: Option<Vec<PathBuf>>,
    /// Each view's per-vertex fields (NPZ), where asked.
    fields: Option<Vec<PathBuf>>,
    /// The manifest.
    manifest: PathBuf,
}

/// Runs the views mode of `shapecue lines`.
pub fn run(device: Option<&str>, a: LinesArgs) -> Result<()> {
    let out = check_flags(&a)?;
    let c = common(&a)?;
    let (scene, mesh, load_ms) = views_scene(&a, &c, &out)?;
    let files = files(&scene, &out, [a.segments.is_some(), a.npz, a.fields]);
    if a.explain {
        return explain(&scene, &files);
    }
    let inputs: Vec<&Path> = c.inputs().into_iter().chain(a.cameras.as_deref()).collect();
    let gpu = Arc::new(Gpu::new(device)?);
    let plan = plan_run(&a, &c, (&mesh, &gpu, &scene), &files, &inputs)?;
    let t_run = Instant::now();
    let mut run = ViewsRun {
        mesh: &mesh,
        segments: files.segments.as_deref(),
        npz: files.npz.as_deref(),
        fields: files.fields.as_deref(),
        dir: &out,
        log: manifest::Log::new(plan.head, plan.kept, files.manifest.clone()),
        written: Vec::new(),
        hand_ms: 0.0,
    };
    // Written before the first view: an interrupted run can be resumed.
    run.log.write(None)?;
    let exec = ExecOptions {
        force: true,
        views: Some(plan.todo.clone()),
        keep_done: true,
        ..Default::default()
    };
    let (result, mut run) = if plan.todo.is_empty() {
        (Ok(None), run)
    } else {
        let (r, run) = with_writer(run, |each| {
            lines_on(&gpu, &scene, LineFiles::Folder(&exec), each)
        });
        (r.map(Some), run)
    };
    let report = match result {
        Ok(r) => r,
        Err(e) => return Err(run.failed(e, &plan.fresh, &files.manifest)),
    };
    let run_ms = ms_since(t_run);
    let timing = match &report {
        Some(r) => timing_doc(r, plan.todo.len(), (load_ms, run_ms, run.hand_ms)),
        None => json!({"load_ms": load_ms, "run_ms": run_ms, "views_computed": 0}),
    };
    run.log.finish(
        report.as_ref().map(|r| r.renderer.clone()),
        Some(timing.clone()),
    )?;
    super::super::print(format_args!(
        "{}: {} views ({} computed, {} kept from the earlier run); views {:.1} ms ({:.2} views/s); {}",
        out.display(),
        scene.views.len(),
        plan.todo.len(),
        scene.views.len() - plan.todo.len(),
        timing["views_ms"].as_f64().unwrap_or(0.0),
        timing["views_per_second"].as_f64().unwrap_or(0.0),
        files.manifest.display()
    ))?;
    Ok(())
}

/// What a views run does, decided before it starts.
struct RunPlan {
    /// The manifest's head.
    head: manifest::Head,
    /// The views of an earlier run kept (`--resume`).
    kept: Vec<manifest::ViewEntry>,
    /// The views to compute.
    todo: Vec<usize>,
    /// What the run creates, to remove again if it fails before listing a
    /// view.
    fresh: Fresh,
}

/// What a run creates: the folders (deepest first), the images, and
/// whether the manifest is new.
struct Fresh {
    dirs: Vec<PathBuf>,
    images: Vec<PathBuf>,
    manifest: bool,
}

/// Plans a views run of `a` on `mesh` with `gpu`: the manifest's head, what
/// an earlier run in the folder leaves (refused without --resume or
/// --force; --resume keeps its whole views; --force removes its files this
/// run does not write), the outputs checked against the `inputs`.
fn plan_run(
    a: &LinesArgs,
    c: &super::Common,
    (mesh, gpu, scene): (&shapecue::Mesh, &Gpu, &shapecue::api::Scene),
    files: &Files,
    inputs: &[&Path],
) -> Result<RunPlan> {
    let out = files.manifest.parent().unwrap_or(Path::new("."));
    let mut head = manifest::Head::new(
        a,
        c,
        mesh,
        &gpu.info.name,
        scene.views.len(),
        options_doc(a, c)?,
    )?;
    head.insert("report", name(&files.report).into());
    head.insert("family_codes", family_codes());
    let earlier = manifest::read(&files.manifest)?;
    if let (Some(r), true) = (earlier.as_ref().and_then(|m| m.renderer()), a.resume) {
        head.insert("renderer", r);
    }
    if earlier.is_some() && !a.force && !a.resume {
        bail!(
            "{} exists: {} holds an earlier run; --resume continues it, --force replaces it",
            files.manifest.display(),
            out.display()
        );
    }
    let kept = match (&earlier, a.resume) {
        (Some(m), true) => m.views_to_keep(&head, &files.manifest, out)?,
        (None, true) => bail!(
            "--resume: {} has no manifest.json of an earlier run to continue; run without \
             --resume (add --force to overwrite what is there)",
            out.display()
        ),
        _ => Vec::new(),
    };
    let todo: Vec<usize> = (0..scene.views.len())
        .filter(|v| !kept.iter().any(|k| k.index == *v))
        .collect();
    let fresh = Fresh {
        dirs: (out.ancestors())
            .filter(|d| !d.as_os_str().is_empty() && !d.exists())
            .map(PathBuf::from)
            .collect(),
        images: (files.images.iter())
            .map(|i| i.1.clone())
            .filter(|p| !p.exists())
            .collect(),
        manifest: earlier.is_none(),
    };
    let per_view = files.per_view();
    let outputs = (todo.iter().flat_map(|&v| per_view[v].iter()))
        .map(|p| p.as_path())
        .chain([files.report.as_path(), files.manifest.as_path()]);
    // --resume overwrites only the files of its own run (the manifest names
    // them); the inputs are never outputs, with or without it.
    check_outputs(inputs.iter().copied(), outputs, a.force || a.resume)?;
    if let (Some(m), true, false) = (&earlier, a.force, a.resume) {
        m.remove_stale(out, &per_view, inputs);
    }
    Ok(RunPlan {
        head,
        kept,
        todo,
        fresh,
    })
}

/// `--explain`: the plan, its lifetimes and run counts, and the files; runs
/// nothing.
fn explain(scene: &shapecue::api::Scene, files: &Files) -> Result<()> {
    let mut s = shapecue::api::explain(scene, &ExecOptions::default())?;
    if let Some(seg) = &files.segments {
        s.push_str(&format!("  and {} segments file(s)\n", seg.len()));
    }
    if let Some(npz) = &files.npz {
        s.push_str(&format!("  and {} NPZ file(s) of segments\n", npz.len()));
    }
    if let Some(f) = &files.fields {
        s.push_str(&format!("  and {} NPZ file(s) of fields\n", f.len()));
    }
    s.push_str(&format!("  and {}\n", files.manifest.display()));
    super::super::print_str(&s)?;
    Ok(())
}

/// The scene of the views: the camera set, the mesh (and the ms loading
/// it took), the lines' options with an SVG per view (and a PNG with
/// `--png`), the files named after the mesh in `out`.
fn views_scene(
    a: &LinesArgs,
    c: &super::Common,
    out: &Path,
) -> Result<(shapecue::api::Scene, Arc<shapecue::Mesh>, f64)> {
    let defaults = CameraDefaults {
        fov: a.fov,
        ortho: a.ortho,
    };
    let views = match (a.views, &a.cameras) {
        (Some(n), None) => fibonacci_views(n, defaults)?,
        (None, Some(f)) => load_camera_file(f, defaults)?,
        _ => unreachable!("check_flags asks for one of --views and --cameras"),
    };
    let t_load = Instant::now();
    let mesh = Arc::new(c.mesh(&a.mesh)?);
    let load_ms = ms_since(t_load);
    let mut opts = picture_options(a, c)?;
    opts.image = a.png;
    opts.svg = true;
    let mut scene = lines_views_scene(mesh.clone(), &opts, views);
    scene.fields = a.fields;
    scene.out_dir = out.to_path_buf();
    scene.prefix = stem(&a.mesh);
    scene.path = c.path.clone();
    Ok((scene, mesh, load_ms))
}

/// Checks the flags of the views mode; returns the output folder.
fn check_flags(a: &LinesArgs) -> Result<PathBuf> {
    if a.output.is_some() {
        bail!(
            "-o writes one picture; --views and --cameras write a file per view into --out DIR: \
             give one or the other"
        );
    }
    match (a.views, &a.cameras) {
        (Some(_), Some(_)) => bail!("give --views N or --cameras FILE, not both"),
        (None, None) => bail!("--out DIR goes with --views N or --cameras FILE.json"),
        (Some(n), None) if !(1..=MAX_VIEWS).contains(&n) => {
            bail!("--views {n}: give 1 to {MAX_VIEWS} views")
        }
        _ => {}
    }
    if a.eye.is_some() || a.target.is_some() || a.up.is_some() {
        bail!(
            "--eye, --target and --up set the one camera of -o; --views fits its cameras to the \
             mesh, and a --cameras file gives each its eye, target and up"
        );
    }
    if let Some(Some(p)) = &a.segments {
        bail!(
            "--segments {}: with --views or --cameras give --segments alone; each view's \
             segments go next to its SVG in --out",
            p.display()
        );
    }
    if a.npz && a.visibility != shapecue::api::VisibilityMethod::Exact {
        bail!(
            "--npz writes the pieces that exact visibility splits and chains; with \
             --visibility depth give --segments for the segments"
        );
    }
    if a.resume && a.force {
        bail!(
            "--resume keeps the earlier run's finished views and --force replaces the run: give \
             one or the other"
        );
    }
    let Some(out) = a.out.clone() else {
        bail!("--views and --cameras write into a folder: give --out DIR");
    };
    if out.is_file() {
        bail!("--out {}: is a file; give a folder", out.display());
    }
    Ok(out)
}

/// The file name prefix of a mesh: its file stem (a generated mesh's name).
fn stem(mesh: &str) -> String {
    let s = Path::new(mesh).file_stem().and_then(|s| s.to_str());
    s.filter(|s| !s.is_empty()).unwrap_or("mesh").to_string()
}

impl Files {
    /// Each view's files (its images, segments, NPZ and fields), by view.
    fn per_view(&self) -> Vec<Vec<PathBuf>> {
        let n = self.images.iter().map(|i| i.0 + 1).max().unwrap_or(0);
        let mut out = vec![Vec::new(); n];
        for (v, p) in &self.images {
            out[*v].push(p.clone());
        }
        for list in [&self.segments, &self.npz, &self.fields]
            .into_iter()
            .flatten()
        {
            for (v, p) in list.iter().enumerate() {
                out[v].push(p.clone());
            }
        }
        out
    }
}

/// Every file of the run: the executor's images and report (frame 0 of a
/// static mesh), the segments next to each SVG, the manifest.
fn files(scene: &shapecue::api::Scene, out: &Path, [segments, npz, fields]: [bool; 3]) -> Files {
    let (images, report) = output_paths(scene, &[0], out);
    let beside = |on: bool, what: &str| {
        on.then(|| {
            (images.iter())
                .filter(|i| i.2.extension().is_some_and(|e| e == "svg"))
                .map(|i| beside_svg(&i.2, what))
                .collect()
        })
    };
    Files {
        segments: beside(segments, "segments.json"),
        npz: beside(npz, "segments.npz"),
        fields: beside(fields, "fields.npz"),
        images: images.into_iter().map(|i| (i.1, i.2)).collect(),
        report,
        manifest: out.join("manifest.json"),
    }
}

/// A file beside an SVG: `X.svg` → `X_segments.json` for `what` =
/// `segments.json`.
fn beside_svg(svg: &Path, what: &str) -> PathBuf {
    let stem = svg
        .file_stem()
        .map(|s| s.to_string_lossy())
        .unwrap_or_default();
    svg.with_file_name(format!("{stem}_{what}"))
}

/// Runs `compute` with a writer thread beside it ([`with_consumer`]):
/// each view `compute` hands over goes to `run.view` on that thread, so that
/// a view's files are written, hashed and listed while the next view is
/// computed. Returns the run back once every view handed over is written
/// (or the writer has stopped on its error, the one reported).
fn with_writer<'a, T>(
    run: ViewsRun<'a>,
    compute: impl FnOnce(&mut dyn FnMut(LineView) -> shapecue::Result<()>) -> shapecue::Result<T>,
) -> (shapecue::Result<T>, ViewsRun<'a>) {
    with_consumer(run, |run, v| run.view(v), compute)
}

/// What the run gathers view by view.
struct ViewsRun<'a> {
    /// The output folder.
    dir: &'a Path,
    /// The mesh (the faces and barycentric coordinates of the segments).
    mesh: &'a shapecue::Mesh,
    /// Each view's segments file, where asked (in view order).
    segments: Option<&'a [PathBuf]>,
    /// Each view's NPZ file, where asked (in view order).
    npz: Option<&'a [PathBuf]>,
    /// Each view's fields file, where asked (in view order).
    fields: Option<&'a [PathBuf]>,
    /// The manifest, written as the views finish.
    log: manifest::Log,
    /// The segments files written so far.
    written: Vec<PathBuf>,
    /// Wall time spent here (writing the segments documents, gathering the
    /// manifest's entries), on the writer thread beside the executor.
    hand_ms: f64,
}

impl ViewsRun<'_> {
    /// One view done: its segments written (whole), its entry kept.
    fn view(&mut self, v: LineView) -> shapecue::Result<()> {
        let t = Instant::now();
        // The executor's images, hashed from the disk; the files written
        // here, hashed from the bytes written.
        let mut listed = (v.files.iter())
            .map(|p| manifest::sha256_file(p).map(|h| json!({"name": name(p), "sha256": h})))
            .collect::<shapecue::Result<Vec<Value>>>()?;
        // The pieces' arrays once, for the JSON and the NPZ.
        let arrays = match (&v.visible, self.segments.is_some() || self.npz.is_some()) {
            (Some(vis), true) => Some((vis, shapecue::api::segment_arrays(vis, self.mesh))),
            _ => None,
        };
        if let Some(paths) = self.segments {
            let visible = arrays.as_ref().map(|(v, a)| (*v, a));
            let doc = segments_doc(visible, &v.segments, v.feature_size);
            let text = serde_json::to_string_pretty(&doc).expect("the segments serialize") + "\n";
            listed.push(self.keep(&paths[v.view], text.into_bytes())?);
        }
        if let (Some(paths), Some((_, a))) = (self.npz, &arrays) {
            let bytes = shapecue::export::npz::segments_npz_bytes(a)?;
            listed.push(self.keep(&paths[v.view], bytes)?);
        }
        if let (Some(paths), Some(f)) = (self.fields, v.fields.as_ref()) {
            let bytes = shapecue::export::npz::fields_npz_bytes(f)?;
            listed.push(self.keep(&paths[v.view], bytes)?);
        }
        let entry = manifest::ViewEntry {
            index: v.view,
            doc: json!({
                "index": v.view,
                "camera": manifest::camera_doc(&v.camera),
                "segments": v.segments.iter().filter(|s| s.strength > 0.0).count(),
                "files": listed,
            }),
        };
        self.log.push(entry);
        self.log.write_now_and_then()?;
        self.hand_ms += ms_since(t);
        Ok(())
    }

    /// Writes `bytes` to `p` whole, remembering it if the run created it;
    /// returns its manifest entry (its name and the SHA-256 of the bytes).
    fn keep(&mut self, p: &Path, bytes: Vec<u8>) -> shapecue::Result<Value> {
        let fresh = !p.exists();
        shapecue::export::output::write_bytes_atomic(p, &bytes)?;
        if fresh {
            self.written.push(p.to_path_buf());
        }
        Ok(json!({"name": name(p), "sha256": manifest::sha256_bytes(&bytes)}))
    }

    /// After a failed run: the views finished before the failure are whole
    /// and listed, and the run can be continued with --resume; where none
    /// is, what the run created goes again (its files, the manifest if it
    /// was new, its folders where left empty). Returns the error to report.
    fn failed(&mut self, e: shapecue::Error, fresh: &Fresh, manifest: &Path) -> anyhow::Error {
        let listed = self.log.views() > 0 && self.log.write(None).is_ok();
        let hint = if listed {
            format!(
                "; the {} view(s) finished are kept: continue with --resume",
                self.log.views()
            )
        } else {
            if fresh.manifest {
                let _ = std::fs::remove_file(manifest);
            }
            for p in fresh.images.iter().chain(&self.written) {
                let _ = std::fs::remove_file(p);
            }
            for d in &fresh.dirs {
                let _ = std::fs::remove_dir(d);
            }
            String::new()
        };
        anyhow::Error::from(e).context(format!(
            "shapecue lines --out {}: the run stopped{hint}",
            self.dir.display()
        ))
    }
}

/// The codes of the NPZ files' `family` array: the line families', and the
/// feature edges', intersection lines' and strokes' layers.
fn family_codes() -> Value {
    let m: serde_json::Map<String, Value> = (shapecue::spec::feature_lines::family_codes())
        .into_iter()
        .map(|(k, n)| (k.to_string(), n.into()))
        .collect();
    Value::Object(m)
}

/// The run's timing: the pose part (topology and pose passes, wall clock),
/// the view part (every view's passes, drawing and writing, wall clock),
/// of which per view the device's (the kernels) and the host's (the rest),
/// views per second over the view part and over the whole run, the time
/// spent writing segments documents (outside the view part), and the
/// passes' own clocks.
fn timing_doc(r: &RunReport, views: usize, (load_ms, run_ms, hand_ms): (f64, f64, f64)) -> Value {
    let t = &r.timing;
    let (pose_ms, views_ms) = (t.phase_ms("pose_wall"), t.phase_ms("view_wall"));
    let n = views.max(1) as f64;
    // The views' device time: their passes' kernels; the rest of their
    // wall time is the host's.
    let device_ms: f64 = (r.passes.iter())
        .filter(|p| p.lifetime.name() == "view" && p.is_kernel())
        .map(|p| p.timing.kernel_ms)
        .sum();
    json!({
        "views_computed": views,
        "load_ms": load_ms,
        "run_ms": run_ms,
        "pose_ms": pose_ms,
        "views_ms": views_ms,
        "per_view_ms": views_ms / n,
        "device_ms_per_view": device_ms / n,
        "host_ms_per_view": (views_ms - device_ms) / n,
        "views_per_second": if views_ms > 0.0 { 1e3 * n / views_ms } else { 0.0 },
        "run_views_per_second": if run_ms > 0.0 { 1e3 * n / run_ms } else { 0.0 },
        "segments_ms": hand_ms,
        "passes_ms": {
            "pose": t.phase_ms("pose"),
            "view": t.phase_ms("view"),
            "render": t.phase_ms("render"),
        },
    })
}

/// The options of the run, as the manifest lists them.
fn options_doc(a: &LinesArgs, c: &super::Common) -> Result<Value> {
    let fams: Vec<&str> = c.fams.iter().map(|f| f.name()).collect();
    let cameras_sha256 = match &a.cameras {
        Some(p) => Some(manifest::sha256_file(p)?),
        None => None,
    };
    Ok(json!({
        "cameras_sha256": cameras_sha256,
        "lines": fams,
        "views": a.views,
        "cameras": a.cameras,
        "size": [c.size.0, c.size.1],
        "line_width": plain(c.width),
        "fov": plain(a.fov),
        "ortho": a.ortho,
        "visibility": a.visibility.name(),
        "hidden": a.hidden.name(),
        "png": a.png,
        "segments": a.segments.is_some(),
        "npz": a.npz,
        "fields": a.fields,
        "feature_size": a.feature_size,
        "sc_threshold": plain(a.sc_threshold),
        "fade": plain(a.fade),
        "rv_threshold": plain(a.rv_threshold),
        "ar_threshold": plain(a.ar_threshold),
        "ph_threshold": plain(a.ph_threshold),
        "sh_threshold": plain(a.sh_threshold),
        "isophotes": a.isophotes,
        "compat": a.compat.name(),
        "normals": a.normals.name(),
        "weld": a.weld,
        "cull": !a.no_cull,
        "test": !a.no_test,
        "fade_lines": !a.no_fade,
        "hermite": a.hermite,
        "hermite_kh": a.hermite_kh,
        "accumulate": a.accumulate.name(),
        "light": a.light,
    }))
}

/// A file's name (the manifest lists the files of its own folder).
fn name(p: &Path) -> String {
    p.file_name()
        .map_or_else(String::new, |n| n.to_string_lossy().into_owned())
}

/// An option's value as written (0.1, not the f32's 0.10000000149).
fn plain(x: f32) -> f64 {
    x.to_string().parse().unwrap_or(f64::from(x))
}

/// Milliseconds since `t`.
fn ms_since(t: Instant) -> f64 {
    t.elapsed().as_secs_f64() * 1e3
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A view of no lines, numbered `view`.
    fn empty_view(view: usize) -> LineView {
        LineView {
            frame: 0,
            view,
            camera: shapecue::api::Camera::look_at(glam::Vec3::Z, glam::Vec3::ZERO),
            segments: Vec::new(),
            visible: None,
            fields: None,
            npz: None,
            image: None,
            layers: None,
            files: Vec::new(),
            passes: Vec::new(),
            timing: Default::default(),
            feature_size: 1.0,
        }
    }

    #[test]
    fn the_writer_thread_writes_the_views_in_order_and_stops_the_run_on_its_error() {
        let dir =
            std::env::temp_dir().join(format!("shapecue-views-writer-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let mesh = shapecue::Mesh::default();
        // Views 0 and 1 can be written; view 2's folder does not exist.
        let paths: Vec<PathBuf> = vec![
            dir.join("v0_segments.json"),
            dir.join("v1_segments.json"),
            dir.join("missing/v2_segments.json"),
            dir.join("v3_segments.json"),
        ];
        let run = ViewsRun {
            dir: &dir,
            mesh: &mesh,
            segments: Some(&paths),
            npz: None,
            fields: None,
            log: manifest::Log::new(
                manifest::Head::empty(),
                Vec::new(),
                dir.join("manifest.json"),
            ),
            written: Vec::new(),
            hand_ms: 0.0,
        };
        let mut handed = 0;
        let (result, run) = with_writer(run, |each| {
            for v in 0..4 {
                each(empty_view(v))?;
                handed += 1;
            }
            Ok(())
        });
        let e = result.expect_err("the writer failed on view 2");
        // The writer's error, naming the file, not the closed channel's.
        assert!(e.to_string().contains("missing"), "{e}");
        assert_eq!(run.written, paths[..2].to_vec());
        assert_eq!(run.log.views(), 2);
        assert!((2..=4).contains(&handed), "{handed}");
        assert!(!paths[3].exists());
        // Without a failure every view is written, in order.
        let run = ViewsRun {
            segments: Some(&paths[..2]),
            written: Vec::new(),
            log: manifest::Log::new(manifest::Head::empty(), Vec::new(), dir.join("m.json")),
            ..run
        };
        let (result, run) = with_writer(run, |each| (0..2).try_for_each(|v| each(empty_view(v))));
        result.unwrap();
        assert_eq!(run.written.len(), 0, "written before: not new");
        assert_eq!(run.log.views(), 2);
        let _ = std::fs::remove_dir_all(&dir);
    }
}
