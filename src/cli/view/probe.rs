//! What the viewer needs to know of a scene's input before the first frame:
//! its frames (to size the frame slider) and the world bounds of its first
//! frame (to orbit around it), from the library's public loaders. The
//! executor loads the input again for every frame it draws.

use shapecue::Result;
use shapecue::mesh::LoadOptions;
use shapecue::scene::file::{ClipRef, Scene, Source};
use std::path::Path;

/// The frames a scene can show and the bounds of its input.
pub struct Probe {
    /// The scene's frame indices (its `[frames]` range within the input).
    pub frames: Vec<usize>,
    /// World bounds (min, max) of the first frame's geometry: the used
    /// vertices of a mesh, the box of a volume.
    pub bounds: ([f64; 3], [f64; 3]),
    /// The value range of a volume (for the iso slider).
    pub values: Option<(f32, f32)>,
    /// Every file the input is read from (so that no output overwrites one).
    pub files: Vec<std::path::PathBuf>,
}

/// Bounds of the vertices that faces use.
fn mesh_bounds(positions: &[[f64; 3]], faces: &[[u32; 3]]) -> ([f64; 3], [f64; 3]) {
    let used = shapecue::mesh::referenced(positions.len(), faces);
    let mut lo = [f64::INFINITY; 3];
    let mut hi = [f64::NEG_INFINITY; 3];
    for (p, _) in positions.iter().zip(&used).filter(|(_, u)| **u) {
        for i in 0..3 {
            lo[i] = lo[i].min(p[i]);
            hi[i] = hi[i].max(p[i]);
        }
    }
    (lo, hi)
}

fn volume_bounds(v: &shapecue::volume::Volume) -> ([f64; 3], [f64; 3]) {
    let hi = std::array::from_fn(|i| v.origin[i] + v.spacing[i] * (v.dims[i].max(1) - 1) as f64);
    (v.origin, hi)
}

/// Loads the scene's input once for its frame count and bounds.
pub fn probe(scene: &Scene) -> Result<Probe> {
    let opts = LoadOptions {
        weld: scene.weld,
        normals: scene.normals,
    };
    let mut values = None;
    let mut files = Vec::new();
    let (available, bounds) = match &scene.source {
        Source::Mesh(p) => {
            files.push(p.clone());
            let m = shapecue::mesh::load(p, &opts)?;
            (1, mesh_bounds(&m.positions, &m.faces))
        }
        Source::Generate(kind, n) => match shapecue::mesh::generated_by_name(kind, *n) {
            Some((_, m)) => (1, mesh_bounds(&m.positions, &m.faces)),
            None => {
                return Err(shapecue::Error::InvalidArgument(format!(
                    "unknown generated mesh {kind}"
                )));
            }
        },
        Source::Meshes(ps) => {
            files.extend(ps.iter().cloned());
            let what = scene.path.display().to_string();
            let (m, _) = shapecue::mesh::load_several(ps, &opts, &what)?;
            (1, mesh_bounds(&m.positions, &m.faces))
        }
        Source::Gltf(p, clip) => {
            files.push(p.clone());
            let m = shapecue::mesh::skinned::load_gltf(p)?;
            let idx = match clip {
                Some(ClipRef::Index(i)) => Some(*i),
                Some(ClipRef::Name(n)) => m.clips.iter().position(|c| &c.name == n),
                None => (!m.clips.is_empty()).then_some(0),
            };
            let frames = idx
                .and_then(|i| m.clips.get(i))
                .map_or(1, |c| (c.duration * scene.fps).floor() as usize + 1);
            (frames, mesh_bounds(&m.rest.positions, &m.rest.faces))
        }
        Source::Lbs(p) => {
            files.push(p.clone());
            files.extend(shapecue::mesh::libigl::siblings(p));
            let a = shapecue::mesh::libigl::load_elephant_set(p)?;
            let (m, _) = a.to_skinned();
            (a.frames, mesh_bounds(&m.rest.positions, &m.rest.faces))
        }
        Source::Flipbook(pattern) => {
            let fb = shapecue::mesh::flipbook::Flipbook::open(pattern, Path::new(""), &opts)?;
            files.extend(fb.frames.iter().cloned());
            let first = fb.frame(0)?;
            (fb.frames.len(), mesh_bounds(&first, &fb.faces))
        }
        Source::Volume(p, ..) => {
            let (v, read) = shapecue::volume::load_with_files(p, None)?;
            files.extend(read);
            values = v.range();
            (1, volume_bounds(&v))
        }
        Source::Sdf(kind, res, ..) => {
            let v = shapecue::volume::sdf::sdf_by_name(kind, *res)?;
            values = v.range();
            (1, volume_bounds(&v))
        }
        Source::Held(m) => (1, mesh_bounds(&m.0.positions, &m.0.faces)),
        Source::HeldVolume(v, ..) => {
            values = v.0.range();
            (1, volume_bounds(&v.0))
        }
    };
    let frames = shapecue::scene::exec::frame_indices(scene, available)?;
    Ok(Probe {
        frames,
        bounds,
        values,
        files,
    })
}
