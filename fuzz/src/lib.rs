//! The fuzz harness: one entry per loader, mapping arbitrary bytes to a file
//! that the loader reads through its public path-based API.
//!
//! The cargo-fuzz targets in `fuzz_targets/` call [`fuzz`]; the ordinary
//! test suite (`tests/fuzz_corpus.rs`) includes this file with `#[path]` and
//! replays the committed corpus through [`run`], so the two can never
//! disagree about what an input means.
//!
//! Loaders take paths (they resolve detached data files next to the
//! header), so each input is written into a scratch folder under its
//! format's extension. That folder also holds fixed companion files for the
//! multi-file formats: `d.raw` and `d1.raw` (64 bytes each, the data files NRRD and MetaImage
//! headers may name), `d.bin` (the buffer the glTF seeds name) and `m.obj`
//! (a mesh scene files may name), so the fuzzer mutates the header against
//! real data.
//!
//! A loader may return any error; it must not panic, abort, hang or
//! allocate more than the input justifies (the fuzzer's `-rss_limit_mb`
//! and `-timeout` catch the last two).

use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicUsize, Ordering};

use shapecue::mesh::skinned::load_gltf;
use shapecue::mesh::{LoadOptions, load};
use shapecue::scene::file::Scene;
use shapecue::volume::{self, RawSpec, ScalarType};

/// Every target, by name; `fuzz/corpus/<name>/` holds its seeds.
pub const TARGETS: [&str; 14] = [
    "obj", "ply", "off", "gltf", "glb", "nrrd", "nhdr", "mhd", "mha", "vtk", "vti", "slc", "raw",
    "scene",
];

/// The fixed data file NRRD and MetaImage headers may name.
pub const DATA_RAW: &[u8] = include_bytes!("../data/d.raw");
/// The buffer the `.gltf` seeds name.
pub const DATA_BIN: &[u8] = include_bytes!("../data/d.bin");
/// The mesh scene files may name.
pub const DATA_OBJ: &[u8] = include_bytes!("../data/m.obj");

/// A scratch folder with the companion files, removed on drop.
pub struct Workspace {
    dir: PathBuf,
}

impl Workspace {
    /// A new folder under the system's temporary folder, unique to this
    /// process and call.
    pub fn new() -> Workspace {
        static NEXT: AtomicUsize = AtomicUsize::new(0);
        let dir = std::env::temp_dir().join(format!(
            "shapecue-fuzz-{}-{}",
            std::process::id(),
            NEXT.fetch_add(1, Ordering::Relaxed)
        ));
        std::fs::create_dir_all(&dir).expect("create the fuzz scratch folder");
        for (name, bytes) in [
            ("d.raw", DATA_RAW),
            ("d1.raw", DATA_RAW),
            ("d.bin", DATA_BIN),
            ("m.obj", DATA_OBJ),
        ] {
            std::fs::write(dir.join(name), bytes).expect("write a fuzz companion file");
        }
        Workspace { dir }
    }

    /// The folder.
    pub fn dir(&self) -> &Path {
        &self.dir
    }
}

impl Default for Workspace {
    fn default() -> Self {
        Workspace::new()
    }
}

impl Drop for Workspace {
    fn drop(&mut self) {
        let _ = std::fs::remove_dir_all(&self.dir);
    }
}

/// The fuzz entry point: [`run`] in a per-thread [`Workspace`], ignoring
/// the result (an error is a correct answer to bad input).
pub fn fuzz(target: &str, data: &[u8]) {
    thread_local! {
        static WS: Workspace = Workspace::new();
    }
    WS.with(|ws| {
        let _ = run(target, data, ws);
    });
}

/// The `.raw` target's spec, taken from the first 8 bytes of the input:
/// three little-endian `u16` dimensions (each plus one), the scalar type
/// (low 3 bits) and byte order (bit 3), and the header size in bytes; the
/// rest of the input is the file. `None` for shorter inputs.
pub fn raw_spec(data: &[u8]) -> Option<(RawSpec, &[u8])> {
    let (head, file) = data.split_first_chunk::<8>()?;
    let dim = |k: usize| 1 + usize::from(u16::from_le_bytes([head[2 * k], head[2 * k + 1]]));
    let scalar = [
        ScalarType::U8,
        ScalarType::I8,
        ScalarType::U16,
        ScalarType::I16,
        ScalarType::U32,
        ScalarType::I32,
        ScalarType::F32,
        ScalarType::F64,
    ][usize::from(head[6] & 7)];
    let mut spec = RawSpec::new([dim(0), dim(1), dim(2)], scalar);
    spec.big_endian = head[6] & 8 != 0;
    spec.header_bytes = usize::from(head[7]);
    Some((spec, file))
}

/// Writes `data` as the target's file in `ws` and reads it with the
/// loader. `Ok` carries a one-line summary of what loaded, `Err` the
/// loader's message (so that displaying every error is exercised too).
///
/// # Panics
///
/// On an unknown target name, or when the scratch file cannot be written.
pub fn run(target: &str, data: &[u8], ws: &Workspace) -> Result<String, String> {
    let (ext, bytes) = match target {
        "raw" => ("raw", raw_spec(data).map_or(data, |(_, f)| f)),
        "scene" => ("toml", data),
        t if TARGETS.contains(&t) => (t, data),
        t => panic!("unknown fuzz target '{t}'"),
    };
    let path = ws.dir().join(format!("in.{ext}"));
    std::fs::write(&path, bytes).expect("write the fuzz input");
    let msg = |e: shapecue::Error| e.to_string();
    match target {
        "obj" | "ply" | "off" => {
            let m = load(&path, &LoadOptions::default()).map_err(msg)?;
            let welded = m.weld().0;
            Ok(format!(
                "{} vertices ({} welded), {} faces",
                m.n_vertices(),
                welded.n_vertices(),
                m.n_faces()
            ))
        }
        "gltf" | "glb" => {
            let s = load_gltf(&path).map_err(msg)?;
            let mut joints = s.joint_matrices(None, 0.0).map_err(msg)?.len();
            for c in 0..s.clips.len() {
                let d = s.clips[c].duration;
                for t in [-1.0, 0.0, 0.37 * d, d, d + 1.0] {
                    joints += s.joint_matrices(Some(c), t).map_err(msg)?.len();
                }
            }
            Ok(format!(
                "{} vertices, {} clips, {joints} joint matrices",
                s.rest.n_vertices(),
                s.clips.len()
            ))
        }
        "raw" => {
            let Some((spec, _)) = raw_spec(data) else {
                return Err("shorter than the 8-byte spec".into());
            };
            let v = volume::load(&path, Some(&spec)).map_err(msg)?;
            Ok(format!("{:?} grid, range {:?}", v.dims, v.range()))
        }
        "scene" => {
            let text = std::str::from_utf8(data).map_err(|e| e.to_string())?;
            let s = Scene::from_str(&path, text).map_err(msg)?;
            Ok(format!("{} views", s.views.len()))
        }
        _ => {
            let v = volume::load(&path, None).map_err(msg)?;
            Ok(format!("{:?} grid, range {:?}", v.dims, v.range()))
        }
    }
}
