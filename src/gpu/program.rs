//! Program building. Kernel files are embedded with `include_str!`; the
//! shared headers of `kernels/common/` are prepended in order, each preceded
//! by a `#line` marker so compiler messages point at the right file and line.
//! A line `#include "common/NAME"` in a kernel file is replaced by that
//! header's text (see [`INCLUDES`]), as often as it appears: a header written
//! over type macros can be instantiated more than once.

use crate::error::{Error, Result};
use opencl3::context::Context;
use opencl3::program::Program;

/// One kernel family's source and the shared headers it uses.
#[derive(Clone, Copy, Debug)]
pub struct KernelFile {
    /// File name under `kernels/` (used in errors and logs).
    pub name: &'static str,
    /// The file's text.
    pub source: &'static str,
    /// `(name, text)` of each header from `kernels/common/`, in include order.
    pub headers: &'static [(&'static str, &'static str)],
}

/// The shared headers every kernel family may use.
pub const COMMON_HEADERS: &[(&str, &str)] = &[
    ("common/real.h", include_str!("../../kernels/common/real.h")),
    (
        "common/atomics.h",
        include_str!("../../kernels/common/atomics.h"),
    ),
];

/// Files a kernel file may `#include` (expanded by [`assemble`], one level
/// deep; the drivers see one text with no include paths), by their path
/// under `kernels/`: shared headers, and the accumulation schemes that
/// `kernels/curvature.cl` includes under `SC_GATHER`.
pub const INCLUDES: &[(&str, &str)] = &[
    (
        "common/curvature_face.h",
        include_str!("../../kernels/common/curvature_face.h"),
    ),
    (
        "common/curvature_lanes.h",
        include_str!("../../kernels/common/curvature_lanes.h"),
    ),
    (
        "curvature_atomic.cl",
        include_str!("../../kernels/curvature_atomic.cl"),
    ),
    (
        "curvature_gather.cl",
        include_str!("../../kernels/curvature_gather.cl"),
    ),
];

/// Looks up a kernel family by name (`"curvature"`, ...).
pub fn kernel_file(name: &str) -> Option<KernelFile> {
    match name {
        "curvature" => Some(KernelFile {
            name: "kernels/curvature.cl",
            source: include_str!("../../kernels/curvature.cl"),
            headers: COMMON_HEADERS,
        }),
        "scan" => Some(KernelFile {
            name: "kernels/scan.cl",
            source: include_str!("../../kernels/scan.cl"),
            headers: COMMON_HEADERS,
        }),
        "radix_sort" => Some(KernelFile {
            name: "kernels/radix_sort.cl",
            source: include_str!("../../kernels/radix_sort.cl"),
            headers: COMMON_HEADERS,
        }),
        "skinning" => Some(KernelFile {
            name: "kernels/skinning.cl",
            source: include_str!("../../kernels/skinning.cl"),
            headers: COMMON_HEADERS,
        }),
        "ao" => Some(KernelFile {
            name: "kernels/ao.cl",
            source: include_str!("../../kernels/ao.cl"),
            headers: COMMON_HEADERS,
        }),
        "feature_lines" => Some(KernelFile {
            name: "kernels/feature_lines.cl",
            source: include_str!("../../kernels/feature_lines.cl"),
            headers: COMMON_HEADERS,
        }),
        "marching_cubes" => Some(KernelFile {
            name: "kernels/marching_cubes.cl",
            source: include_str!("../../kernels/marching_cubes.cl"),
            headers: MC_HEADERS,
        }),
        "vertex_fusion" => Some(KernelFile {
            name: "kernels/vertex_fusion.cl",
            source: include_str!("../../kernels/vertex_fusion.cl"),
            headers: MC_HEADERS,
        }),
        "edges" => Some(KernelFile {
            name: "kernels/edges.cl",
            source: include_str!("../../kernels/edges.cl"),
            headers: COMMON_HEADERS,
        }),
        _ => None,
    }
}

/// Headers of the marching-cubes and vertex-fusion kernels: the common ones and the hash.
const MC_HEADERS: &[(&str, &str)] = &[
    ("common/real.h", include_str!("../../kernels/common/real.h")),
    ("common/hash.h", include_str!("../../kernels/common/hash.h")),
    (
        "common/mc_edge.h",
        include_str!("../../kernels/common/mc_edge.h"),
    ),
];

/// The full text handed to the compiler.
pub fn assemble(file: &KernelFile) -> String {
    let mut s = String::new();
    for (name, text) in file.headers {
        s.push_str(&format!("#line 1 \"kernels/{name}\"\n"));
        s.push_str(text);
        s.push('\n');
    }
    s.push_str(&format!("#line 1 \"{}\"\n", file.name));
    for (i, line) in file.source.lines().enumerate() {
        let included = line
            .trim()
            .strip_prefix("#include")
            .map(|r| r.trim().trim_matches('"'))
            .and_then(|name| INCLUDES.iter().find(|(n, _)| *n == name));
        match included {
            Some((name, text)) => {
                s.push_str(&format!("#line 1 \"kernels/{name}\"\n"));
                s.push_str(text);
                s.push_str(&format!("\n#line {} \"{}\"\n", i + 2, file.name));
            }
            None => {
                s.push_str(line);
                s.push('\n');
            }
        }
    }
    s
}

/// Serialises driver set-up across the whole process (platform and device
/// queries, context creation, program builds): PoCL 3.1's lazy platform
/// initialisation is not thread-safe; two threads querying devices for the
/// first time crashed it (SIGSEGV in clGetDeviceInfo) in this project's
/// parallel tests. Kernel launches are not serialised. Not reentrant.
static DRIVER_LOCK: std::sync::Mutex<()> = std::sync::Mutex::new(());

pub(crate) fn driver_lock() -> std::sync::MutexGuard<'static, ()> {
    DRIVER_LOCK.lock().unwrap_or_else(|p| p.into_inner())
}

/// The options handed to the compiler for `options`: the OpenCL C version
/// first (1.2, unless `options` names one).
pub(crate) fn full_options(options: &str) -> String {
    if options
        .split_whitespace()
        .any(|o| o.starts_with("-cl-std="))
    {
        options.to_string()
    } else {
        format!("-cl-std=CL1.2 {options}")
    }
}

/// Builds `src` (the [`assemble`]d text of `file`) from source with `opts`
/// (from [`full_options`]); a failure carries the build log.
pub(crate) fn build_source(
    context: &Context,
    file: &KernelFile,
    src: &str,
    opts: &str,
) -> Result<Program> {
    let _guard = driver_lock();
    Program::create_and_build_from_source(context, src, opts).map_err(|log| Error::Build {
        file: file.name.to_string(),
        options: opts.to_string(),
        log,
    })
}

/// Creates and builds a program from a binary this driver returned earlier
/// (`CL_PROGRAM_BINARIES`), or says why the driver refused it.
pub(crate) fn build_binary(
    context: &Context,
    device: opencl3::types::cl_device_id,
    binary: &[u8],
    opts: &str,
) -> std::result::Result<Program, String> {
    let _guard = driver_lock();
    // SAFETY: one device and one binary, both alive for the call; the driver
    // checks the binary (PoCL: its magic, version and device hash) and fails
    // the call or the build on a mismatch, which the caller turns into a
    // build from source.
    let mut p = unsafe { Program::create_from_binary(context, &[device], &[binary]) }
        .map_err(|e| e.to_string())?;
    p.build(&[device], opts).map_err(|e| e.to_string())?;
    Ok(p)
}

/// The binary of a built program for its one device, or `None` when the
/// driver gives none (empty, or more than one device).
pub(crate) fn binary_of(program: &Program) -> Option<Vec<u8>> {
    let _guard = driver_lock();
    let mut bins = program.get_binaries().ok()?;
    match bins.len() {
        1 if !bins[0].is_empty() => bins.pop(),
        _ => None,
    }
}
