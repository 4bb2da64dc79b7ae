//! Loading a scene's input on the host (a mesh, a skinned mesh with its
//! poses, a flipbook, a volume or an SDF), the frames it renders, and the
//! paths of the files a run writes.

use crate::error::{Error, Result};
use crate::mesh::LoadOptions;
use crate::mesh::Mesh;
use crate::mesh::skinned::SkinnedMesh;
use crate::scene::file::{ClipRef, Scene, Source};
use crate::spec::marching_cubes::Inside;
use std::path::{Path, PathBuf};

/// The geometry of a scene, loaded on the host.
pub(super) enum Loaded {
    /// A static mesh, and the faces of each file where it joins several
    /// (`[input] meshes`; empty for one).
    Static(Mesh, Vec<usize>),
    Skinned {
        mesh: Box<SkinnedMesh>,
        /// Joint matrices per frame index.
        poses: PoseFn,
        frames: usize,
    },
    Flipbook(crate::mesh::flipbook::Flipbook),
    /// The volume, the isovalue used and whether values were negated.
    Volume(Box<crate::volume::Volume>, f32, bool),
}

/// Joint matrices (flattened, device layout) of a frame.
pub(super) type PoseFn = Box<dyn Fn(usize) -> Result<Vec<f32>>>;

impl Loaded {
    /// Frames available (None: unbounded, a static mesh's one frame repeats).
    pub(super) fn frames(&self) -> usize {
        match self {
            Loaded::Static(..) | Loaded::Volume(..) => 1,
            Loaded::Skinned { frames, .. } => *frames,
            Loaded::Flipbook(f) => f.frames.len(),
        }
    }
}

/// A skinned mesh welded where the scene asks for it, with a note of what
/// welding merged.
fn weld_skinned(
    m: SkinnedMesh,
    weld: bool,
    path: &std::path::Path,
    notes: &mut Vec<String>,
) -> SkinnedMesh {
    if !weld {
        return m;
    }
    let before = m.rest.n_vertices();
    let (w, differ) = m.welded();
    let mut note = format!(
        "{}: welded {before} vertices into {}",
        path.display(),
        w.rest.n_vertices()
    );
    if differ > 0 {
        note.push_str(&format!(
            " ({differ} merged vertices had other skin weights and follow the first)"
        ));
    }
    notes.push(note);
    w
}

/// Loads the scene's input; what was assumed or dropped goes to `notes`.
pub(super) fn load(scene: &Scene, notes: &mut Vec<String>) -> Result<Loaded> {
    let opts = LoadOptions {
        weld: scene.weld,
        normals: scene.normals,
    };
    Ok(match &scene.source {
        Source::Mesh(p) => {
            let m = crate::mesh::load(p, &opts)?;
            notes.extend(m.soup_warning(&p.display().to_string()));
            Loaded::Static(m, Vec::new())
        }
        Source::Meshes(ps) => {
            let what = scene.path.display().to_string();
            let (m, counts) = crate::mesh::load_several(ps, &opts, &what)?;
            Loaded::Static(m, counts)
        }
        Source::Generate(kind, n) => match crate::mesh::generated_by_name(kind, *n) {
            Some((_, m)) => Loaded::Static(m, Vec::new()),
            None => {
                return Err(Error::InvalidArgument(format!(
                    "unknown generated mesh {kind:?}"
                )));
            }
        },
        Source::Gltf(p, clip) => gltf_input(scene, p, clip.as_ref(), notes)?,
        Source::Lbs(p) => lbs_input(scene, p, notes)?,
        // A flipbook's frames are positions: stored normals are not read.
        Source::Flipbook(pat) => Loaded::Flipbook(crate::mesh::flipbook::Flipbook::open(
            pat,
            Path::new(""),
            &LoadOptions {
                normals: crate::mesh::NormalsSource::Computed,
                ..opts
            },
        )?),
        Source::Volume(p, iso, above) => inside_below(crate::volume::load(p, None)?, *iso, *above),
        Source::Sdf(kind, res, iso, above) => {
            inside_below(crate::volume::sdf::sdf_by_name(kind, *res)?, *iso, *above)
        }
        Source::Held(m) => Loaded::Static(m.0.as_ref().clone(), Vec::new()),
        Source::HeldVolume(v, iso, above) => inside_below(v.0.as_ref().clone(), *iso, *above),
    })
}

/// A glTF model and its clip's poses (the rest pose as the one frame when
/// the file has no animation and the scene names no clip).
fn gltf_input(
    scene: &Scene,
    p: &Path,
    clip: Option<&ClipRef>,
    notes: &mut Vec<String>,
) -> Result<Loaded> {
    let m = weld_skinned(crate::mesh::skinned::load_gltf(p)?, scene.weld, p, notes);
    if m.clips.is_empty() && clip.is_none() {
        notes.push(format!(
            "{}: no animation; the rest pose is the one frame",
            p.display()
        ));
        let rest = SkinnedMesh::flatten(&m.joint_matrices(None, 0.0)?);
        return Ok(Loaded::Skinned {
            mesh: Box::new(m),
            poses: Box::new(move |_| Ok(rest.clone())),
            frames: 1,
        });
    }
    let idx = clip_index(&m, p, clip)?;
    let duration = m.clips[idx].duration;
    let fps = scene.fps;
    let frames = (duration * fps).floor() as usize + 1;
    notes.push(format!(
        "clip {idx} {:?}: {duration:.3} s at {fps} fps = {frames} frames",
        m.clips[idx].name
    ));
    let mm = m.clone();
    Ok(Loaded::Skinned {
        mesh: Box::new(m),
        poses: Box::new(move |f| {
            let t = (f as f32 / fps).min(duration);
            Ok(SkinnedMesh::flatten(&mm.joint_matrices(Some(idx), t)?))
        }),
        frames,
    })
}

/// The index of the scene's clip (the first when it names none), checked
/// against the clips of the model at `p`.
fn clip_index(m: &SkinnedMesh, p: &Path, clip: Option<&ClipRef>) -> Result<usize> {
    let idx = match clip.cloned().unwrap_or(ClipRef::Index(0)) {
        ClipRef::Index(i) => i,
        ClipRef::Name(n) => m.clips.iter().position(|c| c.name == n).ok_or_else(|| {
            Error::input(
                p.display().to_string(),
                format!("clip {n:?}"),
                format!(
                    "no such clip; the file has {}",
                    m.clips
                        .iter()
                        .map(|c| format!("\"{}\"", c.name))
                        .collect::<Vec<_>>()
                        .join(", ")
                ),
            )
        })?,
    };
    if idx >= m.clips.len() {
        return Err(Error::input(
            p.display().to_string(),
            format!("clip {idx}"),
            format!("the file has {} clips", m.clips.len()),
        ));
    }
    Ok(idx)
}

/// An LBS set (libigl's elephant format) with its weights cut to four per
/// vertex, and a note of what the cut dropped.
fn lbs_input(scene: &Scene, p: &Path, notes: &mut Vec<String>) -> Result<Loaded> {
    let a = crate::mesh::libigl::load_elephant_set(p)?;
    let (m, trunc) = a.to_skinned();
    let m = weld_skinned(m, scene.weld, p, notes);
    notes.push(format!(
        "{}: {} bones, weights cut to the 4 largest per vertex ({} vertices had more \
         than four, {} more than four above {}; largest dropped weight sum {:.3}, \
         mean {:.4})",
        p.display(),
        m.joint_nodes.len(),
        trunc.vertices_over_4,
        trunc.significant_over_4,
        crate::mesh::libigl::SIGNIFICANT_WEIGHT,
        trunc.max_dropped,
        trunc.mean_dropped
    ));
    let frames = a.frames;
    Ok(Loaded::Skinned {
        mesh: Box::new(m),
        poses: Box::new(move |f| Ok(SkinnedMesh::flatten(&a.frame_matrices(f)?))),
        frames,
    })
}

/// The volume oriented for marching cubes ([`crate::volume::Volume::oriented`]):
/// negated, with its isovalue, when the object is above the isovalue.
fn inside_below(v: crate::volume::Volume, iso: f32, above: bool) -> Loaded {
    let inside = if above { Inside::Above } else { Inside::Below };
    let (v, iso) = v.into_oriented(iso, inside);
    Loaded::Volume(Box::new(v), iso, above)
}

/// The frame indices a scene renders, checked against what the input has.
pub fn frame_indices(scene: &Scene, available: usize) -> Result<Vec<usize>> {
    let (start, end, step) = scene.frames;
    let end = end.unwrap_or(available);
    if end > available || start >= end {
        return Err(Error::input(
            scene.path.display().to_string(),
            "[frames]",
            format!("frames {start}..{end} are outside the input's {available} frame(s)"),
        ));
    }
    Ok((start..end).step_by(step).collect())
}

/// The image files a run writes, in order (frame-major), and the report:
/// `<prefix>_f<frame>_v<view>.png` and `.svg`, the frame in 4 digits and
/// the view in 2, or as many as the last view's index has (so that the
/// names of a run sort in view order), and `<prefix>_report.json`.
pub fn output_paths(
    scene: &Scene,
    frames: &[usize],
    out_dir: &Path,
) -> (Vec<(usize, usize, PathBuf)>, PathBuf) {
    let mut v = Vec::new();
    let digits = (scene.views.len().saturating_sub(1).to_string().len()).max(2);
    for &f in frames {
        for view in 0..scene.views.len() {
            for (on, ext) in [(scene.png, "png"), (scene.svg, "svg"), (scene.npz, "npz")] {
                if on {
                    let name = format!("{}_f{f:04}_v{view:0digits$}.{ext}", scene.prefix);
                    v.push((f, view, out_dir.join(name)));
                }
            }
        }
    }
    (v, out_dir.join(format!("{}_report.json", scene.prefix)))
}
