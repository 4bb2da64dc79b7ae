//! The library's one error type. Every failure a user can cause names what
//! was wrong: the file, the element and the problem for bad input; the kernel
//! file and the build log for an OpenCL build failure.

use std::path::PathBuf;

/// Result alias used throughout the library.
pub type Result<T, E = Error> = std::result::Result<T, E>;

/// What [`Error::gl_sharing_required`] says is missing; the reasons follow it.
pub const GL_SHARING_REQUIRED: &str = "interop = on needs a shared route, CL-GL sharing \
     (cl_khr_gl_sharing) or external memory (cl_khr_external_memory_opaque_fd with \
     GL_EXT_memory_object_fd and Vulkan's VK_KHR_external_memory_fd), and neither can run";

/// Everything that can go wrong in shapecue.
#[derive(Debug, thiserror::Error)]
pub enum Error {
    /// A file could not be opened or read.
    #[error("{}: cannot read: {source}", path.display())]
    Io {
        /// The file.
        path: PathBuf,
        /// What the OS said.
        #[source]
        source: std::io::Error,
    },
    /// A file could not be written.
    #[error("{}: cannot write: {source}", path.display())]
    Write {
        /// The file.
        path: PathBuf,
        /// What the OS said.
        #[source]
        source: std::io::Error,
    },
    /// Input data is malformed: names the file (or source), the element and the problem.
    #[error("{source_name}: {element}: {problem}")]
    InvalidInput {
        /// File path or a description of where the data came from.
        source_name: String,
        /// The element, e.g. `face 12`, `vertex 7`, `header line 3`.
        element: String,
        /// What is wrong with it.
        problem: String,
    },
    /// The file format is not one shapecue reads.
    #[error("{}: unsupported format: {problem}", path.display())]
    UnsupportedFormat {
        /// The file.
        path: PathBuf,
        /// Why.
        problem: String,
    },
    /// No OpenCL platform is installed.
    #[error(
        "no OpenCL platform found ({detail}). Install an OpenCL driver; for the CPU device \
         used in tests: `sudo apt-get install pocl-opencl-icd ocl-icd-opencl-dev` \
         (or run scripts/setup.sh)"
    )]
    NoPlatform {
        /// What the ICD loader reported.
        detail: String,
    },
    /// No device matched the user's selection.
    #[error("no OpenCL device matches '{selector}'; available: {available}")]
    NoDevice {
        /// The device selector (the command line's `--device`, or
        /// `SHAPECUE_DEVICE`).
        selector: String,
        /// A list of the devices found.
        available: String,
    },
    /// An OpenCL call failed.
    #[error("OpenCL error in {what}: {code}")]
    Cl {
        /// Which call or pass.
        what: String,
        /// The OpenCL error name.
        code: String,
    },
    /// An OpenCL program failed to build.
    #[error("OpenCL build of {file} failed (options: {options}):\n{log}")]
    Build {
        /// The kernel file.
        file: String,
        /// Build options passed.
        options: String,
        /// The compiler's build log.
        log: String,
    },
    /// The chosen device lacks something the requested variant needs.
    #[error("device '{device}' cannot run this: {what}")]
    DeviceUnsupported {
        /// Device name.
        device: String,
        /// What is missing.
        what: String,
    },
    /// A device returned a result that contradicts itself (a face naming a
    /// vertex that does not exist): a faulty driver or compiler, caught
    /// before the result is written or drawn.
    #[error("the OpenCL device returned an inconsistent {what}: {detail}")]
    DeviceResult {
        /// Which result.
        what: String,
        /// What is wrong with it.
        detail: String,
    },
    /// A caller passed an argument that makes no sense.
    #[error("invalid argument: {0}")]
    InvalidArgument(String),
    /// The caller stopped a run between two views (a signal, Ctrl-C in
    /// Python); what finished before is whole.
    #[error("interrupted: the run stopped between two views")]
    Interrupted,
    /// Headless OpenGL is unavailable: libEGL could not be loaded, or EGL found
    /// no display or no OpenGL configuration (no Mesa driver).
    #[error(
        "no headless OpenGL ({detail}). Install EGL and Mesa's software rasteriser: \
         `sudo apt-get install libegl1 libgl1-mesa-dri` (or run scripts/setup.sh)"
    )]
    NoGl {
        /// What EGL reported.
        detail: String,
    },
    /// An EGL or OpenGL call failed, or a shader did not compile.
    #[error("OpenGL error in {what}: {detail}")]
    Render {
        /// Which call or step.
        what: String,
        /// The EGL/GL error name, or the shader info log.
        detail: String,
    },
    /// A Vulkan call failed (external memory exported for OpenCL and GL).
    #[error("Vulkan error in {what}: {detail}")]
    Vulkan {
        /// Which call or step.
        what: String,
        /// The Vulkan result or loader message.
        detail: String,
    },
}

impl Error {
    /// Shorthand for [`Error::InvalidInput`].
    pub fn input(
        source_name: impl Into<String>,
        element: impl Into<String>,
        problem: impl Into<String>,
    ) -> Self {
        Error::InvalidInput {
            source_name: source_name.into(),
            element: element.into(),
            problem: problem.into(),
        }
    }

    /// Shorthand for [`Error::Render`]: what failed and the EGL/GL detail.
    pub fn render(what: impl Into<String>, detail: impl std::fmt::Display) -> Self {
        Error::Render {
            what: what.into(),
            detail: detail.to_string(),
        }
    }

    /// Interop mode on without a shared route: a [`Error::DeviceUnsupported`]
    /// whose `what` is [`GL_SHARING_REQUIRED`] followed by `why` (why each
    /// route cannot run), the one device refusal with its own exit code (see
    /// [`Error::exit_code`]).
    pub fn gl_sharing_required(device: &str, why: &str) -> Self {
        Error::DeviceUnsupported {
            device: device.to_string(),
            what: format!("{GL_SHARING_REQUIRED}: {why}"),
        }
    }

    /// The process exit code of a command that failed with this error: 3 for
    /// interop mode on without a shared route ([`Error::gl_sharing_required`]),
    /// 1 for everything else. The one place exit codes are decided.
    pub fn exit_code(&self) -> i32 {
        match self {
            Error::DeviceUnsupported { what, .. } if what.starts_with(GL_SHARING_REQUIRED) => 3,
            _ => 1,
        }
    }

    /// Wraps an OpenCL error code with the name of what failed.
    pub fn cl(what: impl Into<String>, err: impl std::fmt::Display) -> Self {
        Error::Cl {
            what: what.into(),
            code: err.to_string(),
        }
    }
}

/// Values as a message shows them, in place of Rust's debug form: each
/// value's plain `Display` (`1`, `2.5`, `NaN`), joined by `sep` (", " for a
/// tuple in prose, " " for a header's own field syntax).
pub(crate) fn values<T: std::fmt::Display>(
    items: impl IntoIterator<Item = T>,
    sep: &str,
) -> String {
    items
        .into_iter()
        .map(|v| v.to_string())
        .collect::<Vec<_>>()
        .join(sep)
}

/// The choices a message offers, in words: `sphere, torus or gyroid`.
pub(crate) fn one_of(names: &[&str]) -> String {
    match names.split_last() {
        None => String::new(),
        Some((last, [])) => last.to_string(),
        Some((last, rest)) => format!("{} or {last}", rest.join(", ")),
    }
}

#[cfg(test)]
mod message_tests {
    use super::*;

    #[test]
    fn values_and_choices_read_as_words() {
        assert_eq!(values([1.0f32, 2.5, f32::NAN], ", "), "1, 2.5, NaN");
        assert_eq!(values([0i64, 31, 0], " "), "0 31 0");
        assert_eq!(
            one_of(&["sphere", "torus", "gyroid"]),
            "sphere, torus or gyroid"
        );
        assert_eq!(one_of(&["png"]), "png");
        assert_eq!(one_of(&[]), "");
    }
}
