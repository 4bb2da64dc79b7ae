//! The shared test harness, included by every test file with `mod common;`:
//! the OpenCL device, the shared data sets (skipped with a message when
//! absent), scratch folders, the CLI binary, the headless-GL skip rule, and
//! the host arrays that the feature-line entry points read.
//!
//! Shared data: `../shared/data` next to the crate, or the folder named by
//! `$SHAPECUE_SHARED_DATA`. A test whose data is absent prints
//! `skipping: <path> not found …` on stderr and passes.
//!
//! Headless GL: tests that need it skip (with a message) when the machine has
//! none, unless `SHAPECUE_REQUIRE_GL` is set (CI), where they fail instead.

// Each test binary uses only part of the harness.
#![allow(dead_code)]

use opencl3::memory::Buffer;
use shapecue::Error;
use shapecue::gpu::Gpu;
use shapecue::mesh::{self, Mesh, splitmix};
use shapecue::spec::curvature::CurvatureField;
use shapecue::spec::feature_lines::LineInputs;
use std::ffi::OsStr;
use std::path::{Path, PathBuf};
use std::process::{Command, Output};
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::{Arc, OnceLock};

pub mod sdf_fields;

// ---- the device ----

static GPU: OnceLock<Arc<Gpu>> = OnceLock::new();

/// The default OpenCL device, opened once per test binary and shared by its
/// tests (PoCL on the CPU is enough).
pub fn gpu() -> Arc<Gpu> {
    opened().clone()
}

fn opened() -> &'static Arc<Gpu> {
    GPU.get_or_init(|| {
        Arc::new(Gpu::new(None).unwrap_or_else(|e| {
            panic!("these tests need an OpenCL device (PoCL on CPU is enough): {e}")
        }))
    })
}

/// A device buffer holding `data`.
pub fn upload(g: &Gpu, data: &[u32]) -> Buffer<u32> {
    let mut b = g.buffer::<u32>(data.len()).unwrap();
    g.write(&mut b, data).unwrap();
    b
}

/// The first `n` values of a device buffer.
pub fn download(g: &Gpu, b: &Buffer<u32>, n: usize) -> Vec<u32> {
    let mut v = vec![0u32; n];
    g.read(b, &mut v).unwrap();
    v
}

/// `n` deterministic values below `bound` (at most 2^32).
pub fn random(n: usize, bound: u64, seed: u64) -> Vec<u32> {
    let mut s = seed;
    (0..n)
        .map(|_| (splitmix(&mut s) * bound as f64) as u32)
        .collect()
}

// ---- shared data ----

/// Where the shared data sets are by default (the bundled scenes name this
/// folder in their paths).
pub const SHARED_DATA: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/../shared/data");

/// The shared data folder: `$SHAPECUE_SHARED_DATA`, else [`SHARED_DATA`].
/// It may be absent; [`shared`] checks.
pub fn shared_data() -> PathBuf {
    std::env::var_os("SHAPECUE_SHARED_DATA")
        .map(PathBuf::from)
        .unwrap_or_else(|| PathBuf::from(SHARED_DATA))
}

/// `rel` (a file or folder) inside the shared data, or `None` after saying
/// on stderr that the test skips because it is absent.
pub fn shared(rel: impl AsRef<Path>) -> Option<PathBuf> {
    let p = shared_data().join(rel.as_ref());
    if p.exists() {
        return Some(p);
    }
    // The files of the shared data sets that the repository bundles as
    // byte-identical copies (data/README.md gives their checksums) are
    // taken from data/, so their tests also run on a fresh clone.
    let bundled = [
        ("meshes/spot.obj", "spot.obj"),
        ("volumes/Bucky.raw", "Bucky.raw"),
        ("volumes/ironProt.vtk", "ironProt.vtk"),
        ("animations/gltf/Fox.glb", "Fox.glb"),
    ];
    if let Some((_, name)) = bundled.iter().find(|(r, _)| Path::new(r) == rel.as_ref()) {
        let copy = Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("data")
            .join(name);
        if copy.exists() {
            return Some(copy);
        }
    }
    eprintln!(
        "skipping: {} not found (the shared data sets are looked for in \
         $SHAPECUE_SHARED_DATA, else ../shared/data next to the crate)",
        p.display()
    );
    None
}

/// The shared mesh `meshes/<name>`, loaded with the default options, or
/// `None` (after saying so) when absent.
pub fn shared_mesh(name: &str) -> Option<Mesh> {
    let p = shared(Path::new("meshes").join(name))?;
    Some(
        mesh::load(&p, &Default::default())
            .unwrap_or_else(|e| panic!("shared mesh {name} loads: {e}")),
    )
}

/// The shared glTF model `animations/gltf/<name>`, or `None` (after saying
/// so) when absent.
pub fn model_path(name: &str) -> Option<PathBuf> {
    shared(Path::new("animations/gltf").join(name))
}

// ---- scratch folders ----

/// A fresh, empty folder for one test, unique to this test binary, process
/// and call (`tag` names it for a reader), under the system's temp folder.
/// Removed when the returned guard drops, unless the test is failing (then
/// it stays for a look, and the failure's message names it).
pub fn scratch(tag: &str) -> Scratch {
    static N: AtomicUsize = AtomicUsize::new(0);
    let dir = std::env::temp_dir().join(format!(
        "shapecue-tests-{}-{}-{tag}-{}",
        env!("CARGO_CRATE_NAME"),
        std::process::id(),
        N.fetch_add(1, Ordering::Relaxed)
    ));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).expect("create scratch folder");
    Scratch(dir)
}

/// A test's scratch folder (see [`scratch`]): a `Path` by dereference.
pub struct Scratch(PathBuf);

impl std::ops::Deref for Scratch {
    type Target = Path;
    fn deref(&self) -> &Path {
        &self.0
    }
}

impl AsRef<Path> for Scratch {
    fn as_ref(&self) -> &Path {
        &self.0
    }
}

impl Drop for Scratch {
    fn drop(&mut self) {
        if std::thread::panicking() {
            eprintln!("scratch folder kept: {}", self.0.display());
        } else {
            let _ = std::fs::remove_dir_all(&self.0);
        }
    }
}

/// OBJ text of `positions` and 0-based `faces` (positions printed so they
/// read back exactly).
pub fn obj_text(positions: impl IntoIterator<Item = [f64; 3]>, faces: &[[u32; 3]]) -> String {
    let mut s = String::new();
    for p in positions {
        s += &format!("v {} {} {}\n", p[0], p[1], p[2]);
    }
    for f in faces {
        s += &format!("f {} {} {}\n", f[0] + 1, f[1] + 1, f[2] + 1);
    }
    s
}

/// Writes `bytes` to `dir/name` and returns its path.
pub fn write(dir: &Path, name: &str, bytes: impl AsRef<[u8]>) -> PathBuf {
    let p = dir.join(name);
    std::fs::write(&p, bytes).expect("write test file");
    p
}

// ---- the command line ----

/// A command running the `shapecue` binary built for these tests.
pub fn cli() -> Command {
    Command::new(env!("CARGO_BIN_EXE_shapecue"))
}

/// [`cli`] with no EGL vendor to load (`__EGL_VENDOR_LIBRARY_DIRS` at an
/// empty folder made in `dir`): what a server without OpenGL runs.
pub fn cli_no_gl(dir: &Path) -> Command {
    let empty = dir.join("no-egl-vendors");
    std::fs::create_dir_all(&empty).unwrap();
    let mut c = cli();
    c.env("__EGL_VENDOR_LIBRARY_DIRS", &empty);
    c
}

/// Fails the test, with the command's stderr, unless it exited with success.
pub fn assert_succeeded(out: &Output) {
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
}

/// Runs `cmd`, fails the test unless it succeeded (with its stderr), and
/// returns its output with its stdout as text.
pub fn succeeded(cmd: &mut Command) -> (Output, String) {
    let out = cmd.output().expect("run the shapecue binary");
    assert_succeeded(&out);
    let stdout = String::from_utf8_lossy(&out.stdout).into_owned();
    (out, stdout)
}

/// Runs the `shapecue` binary with `args` and returns what it did.
pub fn run_cli<I, S>(args: I) -> Output
where
    I: IntoIterator<Item = S>,
    S: AsRef<OsStr>,
{
    cli().args(args).output().expect("run the shapecue binary")
}

// ---- headless GL ----

/// Whether a missing headless GL is a failure (`SHAPECUE_REQUIRE_GL` set,
/// as in CI) rather than a reason to skip.
pub fn gl_required() -> bool {
    std::env::var_os("SHAPECUE_REQUIRE_GL").is_some()
}

/// `None` (after saying so) when `r` failed only because this machine has
/// no headless GL and GL is not required; else `r`.
pub fn unless_no_gl<T>(r: Result<T, Error>) -> Option<Result<T, Error>> {
    match r {
        Err(e @ Error::NoGl { .. }) if !gl_required() => {
            eprintln!("skipping GL test: {e}");
            None
        }
        r => Some(r),
    }
}

/// Whether a CLI run failed only for want of headless GL (and GL is not
/// required), after saying so: the caller then skips its GL part.
pub fn cli_gl_missing(out: &Output) -> bool {
    let err = String::from_utf8_lossy(&out.stderr);
    if err.contains("no headless OpenGL") && !gl_required() {
        eprintln!("skipping GL part: {err}");
        return true;
    }
    false
}

// ---- feature-line inputs ----

/// The f32 host arrays of a curvature field at world positions `pos`: the
/// inputs of the feature-line entry points that read host arrays.
pub struct LineArrays {
    pub pos: Vec<[f32; 3]>,
    pub nrm: Vec<[f32; 3]>,
    pub d1: Vec<[f32; 3]>,
    pub d2: Vec<[f32; 3]>,
    pub k: Vec<[f32; 2]>,
    pub dk: Vec<[f32; 4]>,
}

impl LineArrays {
    /// Rounds `f` to f32 beside the given positions.
    pub fn new(pos: Vec<[f32; 3]>, f: &CurvatureField) -> LineArrays {
        let c3 = |v: &Vec<[f64; 3]>| v.iter().map(|p| p.map(|c| c as f32)).collect();
        LineArrays {
            pos,
            nrm: c3(&f.normals),
            d1: c3(&f.d1),
            d2: c3(&f.d2),
            k: f.k1
                .iter()
                .zip(&f.k2)
                .map(|(a, b)| [*a as f32, *b as f32])
                .collect(),
            dk: f.dk.iter().map(|d| d.map(|c| c as f32)).collect(),
        }
    }

    /// The arrays as the entry points take them.
    pub fn inputs(&self) -> LineInputs<'_> {
        LineInputs {
            pos: &self.pos,
            nrm: &self.nrm,
            d1: &self.d1,
            d2: &self.d2,
            k: &self.k,
            dk: &self.dk,
        }
    }
}

/// The largest difference of any coordinate between `a` and `b`.
pub fn max_abs_diff(a: &[[f32; 3]], b: &[[f32; 3]]) -> f32 {
    a.iter()
        .zip(b)
        .flat_map(|(p, q)| (0..3).map(move |k| (p[k] - q[k]).abs()))
        .fold(0.0, f32::max)
}

/// `p` rounded to f32.
pub fn to_f32(p: &[[f64; 3]]) -> Vec<[f32; 3]> {
    p.iter().map(|q| q.map(|c| c as f32)).collect()
}

/// Line options drawing only the curvature families `fams` (no contours,
/// no suggestive contours), with `f` setting their controls.
pub fn only(
    fams: &[shapecue::spec::feature_lines::LineFamily],
    f: impl FnOnce(&mut shapecue::spec::feature_lines::CurveOptions),
) -> shapecue::stages::feature_lines::LineOptions {
    let mut curves = shapecue::spec::feature_lines::CurveOptions {
        families: shapecue::spec::feature_lines::FamilySet::of(fams),
        ..Default::default()
    };
    f(&mut curves);
    shapecue::stages::feature_lines::LineOptions {
        contours: false,
        suggestive: false,
        curves,
        ..Default::default()
    }
}
