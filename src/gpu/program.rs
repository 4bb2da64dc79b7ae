//! Program building. Kernel files are embedded with `include_str!`; the
//! shared headers of `kernels/common/` are prepended in order, each preceded
//! by a `#line` marker so compiler messages point at the right file and line.
//! A line `#include "common/NAME"` in a kernel file is replaced by that
//! header's text (see [`KernelFile::includes`]), as often as it appears: a header written
//! over type macros can be instantiated more than once.

use crate::error::{Error, Result};
use opencl3::context::Context;
use opencl3::program::Program;
use serde::Serialize;

/// One kernel family's source and the shared headers it uses (each family's
/// is declared in `stages::kernel_files`).
#[derive(Clone, Copy, Debug)]
pub struct KernelFile {
    /// File name under `kernels/` (used in errors and logs).
    pub name: &'static str,
    /// The file's text.
    pub source: &'static str,
    /// `(name, text)` of each header from `kernels/common/`, in include order.
    pub headers: &'static [(&'static str, &'static str)],
    /// `(name, text)` of each file the source may `#include "name"` (expanded
    /// by [`assemble`], one level deep; the drivers see one text with no
    /// include paths).
    pub includes: &'static [(&'static str, &'static str)],
}

/// The shared headers every kernel family may use.
pub const COMMON_HEADERS: &[(&str, &str)] = &[
    ("common/real.h", include_str!("../../kernels/common/real.h")),
    (
        "common/atomics.h",
        include_str!("../../kernels/common/atomics.h"),
    ),
];

/// `kernels/common/strict.h`: the floating-point rules put first in every
/// program built in [`FpMode::Strict`].
pub const STRICT_HEADER: (&str, &str) = (
    "common/strict.h",
    include_str!("../../kernels/common/strict.h"),
);

/// How strictly a [`super::Gpu`] builds floating-point arithmetic.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum FpMode {
    /// Every program opens with `kernels/common/strict.h` (no contraction
    /// into fused multiply-adds) and, where the device reports
    /// `CL_FP_CORRECTLY_ROUNDED_DIVIDE_SQRT`, is built with
    /// `-cl-fp32-correctly-rounded-divide-sqrt`: the kernels compute what
    /// their CPU twins compute, bit for bit, on every conforming device.
    #[default]
    Strict,
    /// What a GPU compiler does by default: contraction on
    /// (`FP_CONTRACT ON`, `-cl-mad-enable`) and divide and square root to
    /// OpenCL's looser bounds. For measuring what the strict rules cost.
    Relaxed,
}

impl FpMode {
    /// The name in stats, reports and `SHAPECUE_FP`.
    pub fn name(self) -> &'static str {
        match self {
            FpMode::Strict => "strict",
            FpMode::Relaxed => "relaxed",
        }
    }
}

/// The full text handed to the compiler: the floating-point rules of `fp`,
/// the family's headers, then its source with its includes expanded.
pub fn assemble_as(file: &KernelFile, fp: FpMode) -> String {
    let mut s = String::new();
    match fp {
        FpMode::Strict => {
            let (name, text) = STRICT_HEADER;
            s.push_str(&format!("#line 1 \"kernels/{name}\"\n"));
            s.push_str(text);
            s.push('\n');
        }
        FpMode::Relaxed => s.push_str("#pragma OPENCL FP_CONTRACT ON\n"),
    }
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
            .and_then(|name| file.includes.iter().find(|(n, _)| *n == name));
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
/// first (1.2, unless `options` names one), then `options`, then the
/// floating-point options of `fp` (`correctly_rounded`: the device reports
/// `CL_FP_CORRECTLY_ROUNDED_DIVIDE_SQRT`, without which the option is not
/// allowed), then `extra` (`SHAPECUE_CL_OPTIONS`).
pub(crate) fn full_options(
    options: &str,
    fp: FpMode,
    correctly_rounded: bool,
    extra: &str,
) -> String {
    let mut s = if options
        .split_whitespace()
        .any(|o| o.starts_with("-cl-std="))
    {
        options.to_string()
    } else {
        format!("-cl-std=CL1.2 {options}")
    };
    match fp {
        FpMode::Strict if correctly_rounded => {
            s.push_str(" -cl-fp32-correctly-rounded-divide-sqrt")
        }
        FpMode::Strict => {}
        FpMode::Relaxed => s.push_str(" -cl-mad-enable"),
    }
    if !extra.trim().is_empty() {
        s.push(' ');
        s.push_str(extra.trim());
    }
    s.trim().to_string()
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
