//! What the benches share (`mod common;` in each): the device, the shared
//! data sets (skipped with a message when absent), and the quick-run switch.
//!
//! Bench groups are named `<family>/<variant>/<input>` after the stage
//! families (`curvature`, `isosurface`, `radix_sort`, `scan`, `edges`,
//! `skinning`, `pipeline`); the host wall time of a kernel-time variant is
//! the variant `<variant>-wall` (`edges`: `<caps>-frame`, the whole frame
//! with drawing).

// Each bench uses only part of this module.
#![allow(dead_code)]

use shapecue::Mesh;
use shapecue::gpu::Gpu;
use shapecue::mesh::{self, LoadOptions};
use std::path::{Path, PathBuf};
use std::sync::Arc;

/// The default OpenCL device (`SHAPECUE_DEVICE` picks another, as for the
/// CLI), named on stderr, or `None` after saying that `bench` has nothing to
/// measure.
pub fn gpu(bench: &str) -> Option<Arc<Gpu>> {
    match Gpu::new(None) {
        Ok(g) => {
            eprintln!(
                "{bench} bench: device {} ({}, {} CUs)",
                g.info.name, g.info.platform, g.info.compute_units
            );
            Some(Arc::new(g))
        }
        Err(e) => {
            eprintln!("{bench} bench: no OpenCL device ({e}); nothing to bench");
            None
        }
    }
}

/// `SHAPECUE_BENCH_QUICK` is set (and not `0`): each bench keeps its
/// smallest inputs only.
pub fn quick() -> bool {
    std::env::var("SHAPECUE_BENCH_QUICK").is_ok_and(|s| !s.is_empty() && s != "0")
}

/// `rel` inside the shared data (`$SHAPECUE_SHARED_DATA`, else
/// `../shared/data` next to the crate, as for the tests), or `None` after
/// saying that `bench` skips it.
pub fn shared(bench: &str, rel: impl AsRef<Path>) -> Option<PathBuf> {
    let root = std::env::var_os("SHAPECUE_SHARED_DATA")
        .map(PathBuf::from)
        .unwrap_or_else(|| Path::new(env!("CARGO_MANIFEST_DIR")).join("../shared/data"));
    let p = root.join(rel);
    if p.exists() {
        Some(p)
    } else {
        eprintln!("{bench} bench: {} not found, skipping it", p.display());
        None
    }
}

/// The shared mesh `meshes/<name>`, or `None` after saying that `bench`
/// skips it (absent or unreadable).
pub fn shared_mesh(bench: &str, name: &str) -> Option<Mesh> {
    let p = shared(bench, Path::new("meshes").join(name))?;
    match mesh::load(&p, &LoadOptions::default()) {
        Ok(m) => Some(m),
        Err(e) => {
            eprintln!(
                "{bench} bench: cannot load {}: {e}; skipping it",
                p.display()
            );
            None
        }
    }
}
