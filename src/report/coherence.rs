//! `shapecue report coherence`: how much the line families flicker on
//! animations, with hysteresis over the frames off and on, beside a
//! control that moves only as the view does.
//!
//! Each animation runs twice through the scene executor in memory (every
//! frame, one fitted camera, the line families below, each view's pieces
//! with their face and barycentric coordinates): coherence off (every
//! frame's lines on their own) and on (each face that drew a thresholded
//! family in the previous frame tests it at a fraction of its threshold).
//! Pieces are mapped to the rest pose by their face and barycentric
//! coordinates and compared there ([`measure`]).
//!
//! The **control** separates real motion from flicker: the rest mesh, never
//! deformed, seen per part (each vertex's part is its bone of largest
//! weight; a face's, the part most of its corners have) from the camera
//! with that part's best rigid motion (rest to this frame) undone. Only the
//! view moves in it, so its view-dependent lines move as the animation's
//! would without deformation, and its view-independent lines do not move
//! at all (their control is 0).

pub mod measure;

use super::{Block, Cell, Chart, Column, Report, Row, Table};
use crate::api::{LineFiles, LineView, lines_on};
use crate::error::{Error, Result};
use crate::gpu::Gpu;
use crate::mesh::Mesh;
use crate::mesh::skinned::SkinnedMesh;
use crate::render::Camera;
use crate::scene::file::{CameraKind, HeldMesh, LineStyle, Scene, Source, ViewSpec};
use crate::scene::planner::Cue;
use crate::spec::coherence::Coherence;
use crate::spec::feature_lines::{FamilySet, LineFamily};
use glam::DVec3;
use measure::{Flicker, RestSeg, best_rigid, chain_ids_kept, flicker};
use std::path::{Path, PathBuf};
use std::sync::Arc;
use std::time::Instant;

/// The families whose lines do not depend on the view: everything they do
/// without deformation is flicker.
pub const VIEW_INDEPENDENT: [LineFamily; 4] = [
    LineFamily::Ridges,
    LineFamily::Valleys,
    LineFamily::KZero,
    LineFamily::HZero,
];

/// The view-dependent families: their motion on the surface is partly real
/// (the control measures that part).
pub const VIEW_DEPENDENT: [LineFamily; 4] = [
    LineFamily::Contours,
    LineFamily::Suggestive,
    LineFamily::ApparentRidges,
    LineFamily::SuggestiveHighlights,
];

/// τ, the distance within which a line counts as the same line, as a
/// fraction of the rest mesh's bounding-box diagonal.
pub const TAU: f64 = 0.005;

/// What `shapecue report coherence` measures.
#[derive(Clone, Debug, Default)]
pub struct CoherenceOptions {
    /// Scene files of animations (their input, frames and first camera);
    /// none: [`default_scenes`].
    pub scenes: Vec<PathBuf>,
    /// Image size the camera frames.
    pub size: Option<[u32; 2]>,
}

/// The default animations: the libigl elephant (60 frames), Khronos
/// BrainStem (30 frames) and Fox (its walk) of the shared data where they
/// are, and the Fox bundled with the repository.
pub fn default_scenes() -> Result<Vec<Scene>> {
    let shared = super::shared_data().join("animations");
    let bundled = Path::new(env!("CARGO_MANIFEST_DIR")).join("data/Fox.glb");
    let mut texts = Vec::new();
    let elephant = shared.join("elephant/elephant.obj");
    if elephant.exists() {
        texts.push((
            "elephant",
            format!(
                "[input]\nlbs = {:?}\n[frames]\nstart = 0\nend = 60\n\
                 [[camera]]\ndirection = [1.0, 0.25, 0.8]\n",
                elephant.display().to_string()
            ),
        ));
    }
    let brainstem = shared.join("gltf/BrainStem.glb");
    if brainstem.exists() {
        texts.push((
            "BrainStem",
            format!(
                "[input]\ngltf = {:?}\nclip = 0\n[frames]\nstart = 0\nend = 60\nstep = 2\n\
                 [[camera]]\ndirection = [0.2, -1.0, 0.15]\nup = [0.0, 0.0, 1.0]\n",
                brainstem.display().to_string()
            ),
        ));
    }
    texts.push((
        "Fox",
        format!(
            "[input]\ngltf = {:?}\nclip = \"Walk\"\nweld = true\n\
             [[camera]]\ndirection = [1.0, 0.4, 0.2]\n",
            bundled.display().to_string()
        ),
    ));
    texts
        .into_iter()
        .map(|(name, body)| {
            let text = format!("{body}[effects]\ncontours = {{}}\n");
            let mut s = Scene::from_str(Path::new(name), &text)?;
            s.name = name.into();
            Ok(s)
        })
        .collect()
}

/// The scene of one measured run of `base`: its input, frames and first
/// camera; `families` drawn, each view's pieces kept as NPZ arrays in
/// memory, nothing written; `coherence` as asked.
fn measured(base: &Scene, families: &[LineFamily], coherence: Coherence, size: [u32; 2]) -> Scene {
    let mut s = base.clone();
    s.views.truncate(1);
    s.size = size;
    s.png = false;
    s.svg = false;
    s.npz = true;
    let fx = &mut s.effects;
    fx.cues.clear();
    fx.lines.styles.clear();
    for &f in families {
        fx.cues.push(match f {
            LineFamily::Contours => Cue::Contours,
            LineFamily::Suggestive => Cue::SuggestiveContours,
            f => *(Cue::ALL.iter())
                .find(|c| c.family() == Some(f))
                .expect("every curvature line family has its cue"),
        });
        if !matches!(f, LineFamily::Contours | LineFamily::Suggestive) {
            fx.lines.styles.push(LineStyle::default_for(f));
        }
    }
    fx.lines.curves.families = FamilySet::of(families).curves();
    fx.lines.coherence = coherence;
    s
}

/// One run of an animation: each frame's segments in rest coordinates,
/// the camera, each frame's pose, and each frame's line passes' ms.
struct Run {
    frames: Vec<Vec<RestSeg>>,
    camera: Option<Camera>,
    poses: Vec<Vec<[f64; 3]>>,
    line_ms: Vec<f64>,
    wall_ms: f64,
}

/// The pieces of a view in rest coordinates (`rest`: positions), keeping
/// those whose face `keep` accepts.
fn rest_segments(
    v: &LineView,
    rest: &[[f64; 3]],
    faces: &[[u32; 3]],
    keep: impl Fn(usize) -> bool,
) -> Vec<RestSeg> {
    let Some(n) = &v.npz else { return Vec::new() };
    let a = &n.arrays;
    let at = |f: usize, w: [f32; 3]| -> DVec3 {
        (0..3)
            .map(|i| DVec3::from(rest[faces[f][i] as usize]) * f64::from(w[i]))
            .sum()
    };
    (0..a.face.len())
        .filter(|&i| a.face[i] >= 0 && keep(a.face[i] as usize))
        .map(|i| {
            let f = a.face[i] as usize;
            RestSeg {
                family: a.family[i],
                a: at(f, a.bary[i][0]),
                b: at(f, a.bary[i][1]),
                chain_id: a.chain_id.as_ref().map_or(u32::MAX, |c| c[i]),
            }
        })
        .collect()
}

/// The line passes' ms of a view (kernel time of the contours, suggestive
/// contours and curve families).
fn line_ms(v: &LineView) -> f64 {
    use crate::scene::planner::Pass;
    (v.passes.iter())
        .filter(|p| {
            matches!(
                p.pass,
                Pass::Contours | Pass::SuggestiveContours | Pass::LinesCurves
            )
        })
        .map(|p| p.ms())
        .sum()
}

/// Runs `scene` in memory and maps each frame's pieces to `rest`.
fn run(gpu: &Arc<Gpu>, scene: &Scene, rest: &Mesh) -> Result<Run> {
    let mut out = Run {
        frames: Vec::new(),
        camera: None,
        poses: Vec::new(),
        line_ms: Vec::new(),
        wall_ms: 0.0,
    };
    let t = Instant::now();
    lines_on(gpu, scene, LineFiles::Memory, &mut |v| {
        out.frames
            .push(rest_segments(&v, &rest.positions, &rest.faces, |_| true));
        out.line_ms.push(line_ms(&v));
        out.camera.get_or_insert(v.camera);
        out.poses
            .push(v.npz.map(|n| n.positions).unwrap_or_default());
        Ok(())
    })?;
    out.wall_ms = t.elapsed().as_secs_f64() * 1e3;
    Ok(out)
}

/// The rest mesh of a scene's animation and each vertex's part (its bone of
/// largest weight), as the executor loads it.
fn rest_and_parts(scene: &Scene) -> Result<(Mesh, Vec<u32>)> {
    let skinned: SkinnedMesh = match &scene.source {
        Source::Gltf(p, _) => crate::mesh::skinned::load_gltf(p)?,
        Source::Lbs(p) => crate::mesh::libigl::load_elephant_set(p)?.to_skinned().0,
        _ => {
            return Err(Error::InvalidArgument(format!(
                "{}: coherence is measured on skinned animations (a glTF skin or a libigl \
                 set)",
                scene.path.display()
            )));
        }
    };
    let m = if scene.weld {
        skinned.welded().0
    } else {
        skinned
    };
    let parts = (m.joints.iter().zip(&m.weights))
        .map(|(j, w)| {
            let best = (0..4).max_by(|&a, &b| w[a].total_cmp(&w[b])).unwrap_or(0);
            j[best]
        })
        .collect();
    Ok((m.rest, parts))
}

/// Each face's part: the part most of its corners have (the first
/// corner's on a three-way tie).
fn face_parts(faces: &[[u32; 3]], parts: &[u32]) -> Vec<u32> {
    faces
        .iter()
        .map(|f| {
            let p = f.map(|v| parts[v as usize]);
            if p[1] == p[2] && p[0] != p[1] {
                p[1]
            } else {
                p[0]
            }
        })
        .collect()
}

/// The control of a run: the rest mesh seen, per part and frame, from the
/// camera with the part's best rigid motion undone; each frame's segments
/// of the view-dependent `families` on that part's faces.
fn control(
    gpu: &Arc<Gpu>,
    base: &Scene,
    rest: &Mesh,
    parts: &[u32],
    main: &Run,
    size: [u32; 2],
) -> Result<Vec<Vec<RestSeg>>> {
    let cam = main.camera.expect("a run hands at least one view");
    let fparts = face_parts(&rest.faces, parts);
    let mut ids: Vec<u32> = parts.to_vec();
    ids.sort_unstable();
    ids.dedup();
    let fov = base.views.first().map_or(45.0, |v| v.fov);
    let mut views = Vec::new();
    let mut owner = Vec::new();
    for (k, pose) in main.poses.iter().enumerate() {
        for &p in &ids {
            let (r0, p0): (Vec<DVec3>, Vec<DVec3>) = (0..rest.n_vertices())
                .filter(|&v| parts[v] == p)
                .map(|v| (DVec3::from(rest.positions[v]), DVec3::from(pose[v])))
                .unzip();
            let Some((r, t)) = best_rigid(&r0, &p0) else {
                continue;
            };
            let back = |x: glam::Vec3| r.transpose() * (x.as_dvec3() - t);
            let eye = back(cam.eye);
            let target = back(cam.target);
            let up = r.transpose() * cam.up.as_dvec3();
            views.push(ViewSpec {
                kind: CameraKind::LookAt {
                    eye: eye.as_vec3().to_array(),
                    target: Some(target.as_vec3().to_array()),
                },
                up: Some(up.as_vec3().to_array()),
                fov,
                ortho: false,
            });
            owner.push((k, p));
        }
    }
    let mut s = measured(base, &VIEW_DEPENDENT, Coherence::Off, size);
    s.source = Source::Held(HeldMesh(Arc::new(rest.clone())));
    s.frames = (0, None, 1);
    s.views = views;
    let mut frames = vec![Vec::new(); main.poses.len()];
    lines_on(gpu, &s, LineFiles::Memory, &mut |v| {
        let (k, p) = owner[v.view];
        let segs = rest_segments(&v, &rest.positions, &rest.faces, |f| fparts[f] == p);
        frames[k].extend(segs);
        Ok(())
    })?;
    Ok(frames)
}

/// Measures the report.
///
/// # Errors
/// A scene that cannot be loaded or is not a skinned animation, device
/// failures.
pub fn report(gpu: &Arc<Gpu>, o: &CoherenceOptions) -> Result<Report> {
    let scenes = match o.scenes.is_empty() {
        true => default_scenes()?,
        false => (o.scenes.iter())
            .map(|p| Scene::load(p))
            .collect::<Result<Vec<_>>>()?,
    };
    let size = o.size.unwrap_or([640, 480]);
    let mut r = Report::new("coherence", gpu.info.name.clone());
    r.text(format!(
        "Flicker of the line families on animations, with coherence over the frames off and \
         on (`[lines] coherence`: held faces test a family at {} of its threshold, a line found \
         away from every line of its family waits {} frame(s) before it is drawn, and K, H and \
         emax keep their previous sign within {}·s⁻², s⁻¹, s⁻², s the feature size). Every \
         frame of each animation, one fitted camera at {}x{}, every piece (visible and \
         hidden), mapped to the rest pose by its face and barycentric coordinates. Pop: the \
         share of line length farther than τ = {}·(the rest mesh's bounding-box diagonal) from \
         the next frame's lines of the family, both directions. Short-lived: the share of line \
         length that persists (within τ) fewer than 3 frames. Control: the rest mesh seen per \
         part (bone of largest weight) from the camera with that part's best rigid motion \
         undone, so that only the view moves: view-dependent lines move there as much as the \
         view explains; view-independent ones do not move (0). Length: the mean line length \
         per frame, on against off. Chain ids kept: with coherence on, the share of line \
         length whose chain keeps its id into the next frame (chains take the id of the previous \
         frame's chain most of their length lies on). Line ms: the line passes' kernel time per \
         frame.\n",
        Coherence::DEFAULT_LOW,
        Coherence::DEFAULT_BIRTH,
        Coherence::DEFAULT_BAND,
        size[0],
        size[1],
        TAU
    ));
    let mut tables = Tables::new();
    for (k, base) in scenes.iter().enumerate() {
        tables.animation(gpu, base, size, k == 0)?;
    }
    tables.into_report(&mut r, &scenes[0].name);
    Ok(r)
}

/// The report's tables and charts, filled one animation at a time.
struct Tables {
    flicker: Table,
    cost: Table,
    /// Per animation and family: the short-lived share off, on and of the
    /// control (%).
    bars: Vec<(String, [f64; 3])>,
    /// The pop share over the frames of the first animation's
    /// view-independent families, off and on.
    over_frames: Vec<(String, Vec<(f64, f64)>)>,
}

impl Tables {
    fn new() -> Tables {
        let columns = |c: &[(&str, &str)]| c.iter().map(|(t, k)| Column::new(t, k)).collect();
        Tables {
            flicker: Table::new(
                "flicker",
                columns(&[
                    ("animation", "animation"),
                    ("family", "family"),
                    ("kind", "kind"),
                    ("pop off", "pop_off"),
                    ("pop on", "pop_on"),
                    ("short-lived off", "short_lived_off"),
                    ("short-lived on", "short_lived_on"),
                    ("control pop", "control_pop"),
                    ("control short-lived", "control_short_lived"),
                    ("length on/off", "length_ratio"),
                    ("chain ids kept (on)", "chain_ids_kept_on"),
                ]),
            ),
            cost: Table::new(
                "cost",
                columns(&[
                    ("animation", "animation"),
                    ("vertices", "vertices"),
                    ("frames", "frames"),
                    ("line ms/frame off", "line_ms_off"),
                    ("line ms/frame on", "line_ms_on"),
                    ("wall ms/frame off", "wall_ms_off"),
                    ("wall ms/frame on", "wall_ms_on"),
                ]),
            ),
            bars: Vec::new(),
            over_frames: Vec::new(),
        }
    }

    /// Measures the animation of `base`: coherence off and on and the
    /// control, a row per family and one of cost; with `plot_frames`, its
    /// view-independent families' pop share over the frames.
    fn animation(
        &mut self,
        gpu: &Arc<Gpu>,
        base: &Scene,
        size: [u32; 2],
        plot_frames: bool,
    ) -> Result<()> {
        let all: Vec<LineFamily> = (VIEW_INDEPENDENT.iter())
            .chain(&VIEW_DEPENDENT)
            .copied()
            .collect();
        let (rest, parts) = rest_and_parts(base)?;
        let diag = {
            let (lo, hi) = rest.bounds();
            (0..3).map(|i| (hi[i] - lo[i]).powi(2)).sum::<f64>().sqrt()
        };
        let tau = TAU * diag;
        // The kernels are built before any timing: the first two frames.
        let mut warm = measured(base, &all, Coherence::On, size);
        let (start, _, step) = warm.frames;
        warm.frames = (start, Some(start + 2 * step), step);
        run(gpu, &warm, &rest)?;
        let off = run(gpu, &measured(base, &all, Coherence::Off, size), &rest)?;
        let on = run(gpu, &measured(base, &all, Coherence::On, size), &rest)?;
        let ctl = control(gpu, base, &rest, &parts, &off, size)?;
        for &fam in &all {
            let code = fam as u32;
            let (a, b) = (
                flicker(&off.frames, code, tau),
                flicker(&on.frames, code, tau),
            );
            let c = match VIEW_DEPENDENT.contains(&fam) {
                true => flicker(&ctl, code, tau),
                false => Flicker {
                    pop: 0.0,
                    short_lived: 0.0,
                    ..Flicker::default()
                },
            };
            let kept = chain_ids_kept(&on.frames, code);
            self.family(&base.name, fam, [&a, &b, &c], kept, plot_frames);
        }
        let n = off.frames.len();
        let per = |v: &[f64]| v.iter().sum::<f64>() / v.len().max(1) as f64;
        let ms = |x: f64| Cell::num(x, format!("{x:.2}"));
        self.cost.rows.push(Row::new(vec![
            Cell::text(&base.name),
            Cell::int(rest.n_vertices()),
            Cell::int(n),
            ms(per(&off.line_ms)),
            ms(per(&on.line_ms)),
            ms(off.wall_ms / n.max(1) as f64),
            ms(on.wall_ms / n.max(1) as f64),
        ]));
        Ok(())
    }

    /// The row, bars and (with `plot_frames`, for a view-independent
    /// family) pop share over the frames of one family of `animation`:
    /// its flicker off, on and in the control, and the share of its length
    /// whose chain id the next frame keeps.
    fn family(
        &mut self,
        animation: &str,
        fam: LineFamily,
        [a, b, c]: [&Flicker; 3],
        kept: f64,
        plot_frames: bool,
    ) {
        let pct = |x: f64| match x.is_finite() {
            true => Cell::num(100.0 * x, format!("{:.1} %", 100.0 * x)),
            false => Cell::text("–"),
        };
        let dependent = VIEW_DEPENDENT.contains(&fam);
        let ratio = b.mean_length / a.mean_length;
        self.flicker.rows.push(Row::new(vec![
            Cell::text(animation),
            Cell::text(fam.name()),
            Cell::text(match dependent {
                true => "view-dependent",
                false => "view-independent",
            }),
            pct(a.pop),
            pct(b.pop),
            pct(a.short_lived),
            pct(b.short_lived),
            pct(c.pop),
            pct(c.short_lived),
            match ratio.is_finite() {
                true => Cell::num(ratio, format!("{ratio:.3}")),
                false => Cell::text("–"),
            },
            pct(kept),
        ]));
        if plot_frames && !dependent {
            for (f, what) in [(a, "off"), (b, "on")] {
                let pts = (f.pop_per_pair.iter().enumerate())
                    .map(|(k, &p)| (k as f64, 100.0 * p))
                    .collect();
                self.over_frames
                    .push((format!("{} {what}", fam.name()), pts));
            }
        }
        self.bars.push((
            format!("{animation} {}", fam.name()),
            [a.short_lived, b.short_lived, c.short_lived].map(|x| 100.0 * x),
        ));
    }

    /// The tables and charts into `r` (`first`: the animation whose frames
    /// are plotted).
    fn into_report(self, r: &mut Report, first: &str) {
        r.blocks.push(Block::Table(self.flicker));
        r.text("\nThe cost of each run (coherence off, then on):\n".to_string());
        r.blocks.push(Block::Table(self.cost));
        r.charts.push(Chart::Lines {
            title: format!(
                "{first}: pop share between frame k and k + 1 (%), coherence off and on"
            ),
            x_label: "frame k".into(),
            y_label: "pop share %".into(),
            series: self.over_frames,
        });
        let bars = self.bars;
        r.charts.push(Chart::Bars {
            title: "Short-lived share of line length (%): coherence off, on, and the control"
                .into(),
            y_label: "short-lived %".into(),
            log_y: false,
            groups: bars.iter().map(|b| b.0.clone()).collect(),
            series: ["off", "on", "control"]
                .iter()
                .enumerate()
                .map(|(i, s)| (s.to_string(), bars.iter().map(|b| b.1[i]).collect()))
                .collect(),
        });
    }
}
