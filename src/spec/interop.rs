//! How the buffers the kernels write reach the GL buffers the renderer
//! draws from: the `--interop` option, what a device, a GL context and a
//! Vulkan driver report, and the route chosen from them ([`decide_interop`]),
//! a pure function of data, tested for every combination without a device.
//!
//! Three routes, in the order `auto` tries them:
//! 1. **CL-GL sharing** (`cl_khr_gl_sharing`): OpenCL buffers made from GL
//!    buffers (`clCreateFromGLBuffer`) in an OpenCL context created on the
//!    renderer's GL context.
//! 2. **External memory**: one Vulkan allocation exported as opaque file
//!    descriptors (`VK_KHR_external_memory_fd`), imported by OpenCL
//!    (`cl_khr_external_memory_opaque_fd`) and by GL
//!    (`GL_EXT_memory_object_fd`); all three must be offered.
//! 3. **Host**: read the outputs back and upload them to GL.
//!
//! Nothing is probed by calling an entry point the driver may lack:
//! `clCreateFromGLBuffer` on a device without `cl_khr_gl_sharing` (PoCL)
//! terminates the process, so the device's extension string decides.

use serde::Serialize;

use crate::error::{Error, Result};

/// The OpenCL extension of route 1.
pub const CL_GL_SHARING: &str = "cl_khr_gl_sharing";
/// The OpenCL extension of route 2.
pub const CL_EXTERNAL_MEMORY_FD: &str = "cl_khr_external_memory_opaque_fd";
/// The GL extension of route 2.
pub const GL_MEMORY_OBJECT_FD: &str = "GL_EXT_memory_object_fd";
/// The Vulkan device extension of route 2.
pub const VK_EXTERNAL_MEMORY_FD: &str = "VK_KHR_external_memory_fd";

/// Whether this build carries out CL-GL sharing. Sharing needs the OpenCL
/// context to be created on the renderer's GL context (`CL_GL_CONTEXT_KHR`,
/// `CL_EGL_DISPLAY_KHR`); the device layer creates its context before and
/// apart from any renderer, so a device that reports the extension is passed
/// over, with this said in the reason, for the next route.
pub const GL_SHARING_BUILT: bool = false;

/// What `--interop` asked for: kernels writing the buffers GL draws from.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum InteropMode {
    /// The first shared route on offer (CL-GL sharing, then external
    /// memory), the host path otherwise.
    Auto,
    /// Require a shared route.
    On,
    /// Always copy through the host.
    Off,
}

impl InteropMode {
    /// Every mode, in `--help` order.
    pub const ALL: [InteropMode; 3] = [InteropMode::Auto, InteropMode::On, InteropMode::Off];

    /// The name used on the command line and in stats.
    pub fn name(self) -> &'static str {
        match self {
            InteropMode::Auto => "auto",
            InteropMode::On => "on",
            InteropMode::Off => "off",
        }
    }
}

crate::spec::named_choice!(InteropMode, "interop mode");

/// A route from the kernels' buffers to GL.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum InteropRoute {
    /// `cl_khr_gl_sharing`.
    GlSharing,
    /// A Vulkan allocation imported by OpenCL and GL as opaque fds.
    ExternalMemory,
    /// Read back and upload.
    Host,
}

impl InteropRoute {
    /// The name used in stats and reports.
    pub fn name(self) -> &'static str {
        match self {
            InteropRoute::GlSharing => "gl_sharing",
            InteropRoute::ExternalMemory => "external_memory",
            InteropRoute::Host => "host",
        }
    }

    /// Whether the kernels write what GL draws (no host copy).
    pub fn shared(self) -> bool {
        self != InteropRoute::Host
    }
}

/// What the OpenCL device, the GL context and Vulkan report. `None`: not
/// looked at (a GL context and a Vulkan instance are only made for the
/// question when the device could use their answer).
#[derive(Clone, Debug, Default, PartialEq, Eq, Serialize)]
pub struct InteropOffer {
    /// The OpenCL device's name.
    pub device: String,
    /// The device reports `cl_khr_gl_sharing`.
    pub cl_gl_sharing: bool,
    /// The device reports `cl_khr_external_memory_opaque_fd`.
    pub cl_external_memory: bool,
    /// The renderer's GL context reports `GL_EXT_memory_object_fd`.
    pub gl_memory_object_fd: Option<bool>,
    /// A Vulkan device with `VK_KHR_external_memory_fd` was found (through
    /// a Vulkan loader found at run time).
    pub vk_external_memory_fd: Option<bool>,
    /// Why Vulkan offers no such device, when it does not (no loader, no
    /// device, no extension), in words.
    pub vk_detail: Option<String>,
}

impl InteropOffer {
    /// Whether the GL context and Vulkan are worth asking: the device can
    /// import external memory.
    pub fn wants_probe(&self) -> bool {
        self.cl_external_memory
    }
}

/// The route chosen, and why the others were not.
#[derive(Clone, Debug, PartialEq, Eq, Serialize)]
pub struct InteropDecision {
    /// The route that runs.
    pub route: InteropRoute,
    /// `true`: kernels write what GL draws; `false`: read back and upload.
    pub shared: bool,
    /// Why this route, in words (for stats).
    pub reason: String,
    /// Why each route before it was not taken, in `auto`'s order.
    pub passed_over: Vec<String>,
}

/// Why CL-GL sharing cannot run, or `None` when it can.
fn sharing_missing(o: &InteropOffer) -> Option<String> {
    if !o.cl_gl_sharing {
        Some(format!(
            "GL sharing: device '{}' does not report {CL_GL_SHARING}",
            o.device
        ))
    } else if !GL_SHARING_BUILT {
        Some(format!(
            "GL sharing: device '{}' reports {CL_GL_SHARING}, but this build makes its OpenCL \
             context apart from the renderer's GL context, which sharing needs",
            o.device
        ))
    } else {
        None
    }
}

/// Why external memory cannot run, or `None` when it can.
fn external_missing(o: &InteropOffer) -> Option<String> {
    let not_asked = "was not asked";
    let missing = if !o.cl_external_memory {
        format!(
            "device '{}' does not report {CL_EXTERNAL_MEMORY_FD}",
            o.device
        )
    } else {
        match (o.gl_memory_object_fd, o.vk_external_memory_fd) {
            (Some(true), Some(true)) => return None,
            (None, _) => format!("the GL context {not_asked} for {GL_MEMORY_OBJECT_FD}"),
            (Some(false), _) => format!("the GL context does not report {GL_MEMORY_OBJECT_FD}"),
            (_, None) => format!("Vulkan {not_asked} for {VK_EXTERNAL_MEMORY_FD}"),
            (_, Some(false)) => match &o.vk_detail {
                Some(d) => format!("no Vulkan device with {VK_EXTERNAL_MEMORY_FD} ({d})"),
                None => format!("no Vulkan device with {VK_EXTERNAL_MEMORY_FD}"),
            },
        }
    };
    Some(format!("external memory: {missing}"))
}

/// Decides the interop route from the mode and what is on offer.
///
/// `auto` takes CL-GL sharing, then external memory, then the host path;
/// `on` takes the first shared route and fails without one; `off` takes the
/// host path. The decision says why the routes before the one taken were not.
///
/// # Errors
/// [`Error::DeviceUnsupported`] for `on` without a shared route
/// ([`Error::gl_sharing_required`], naming both routes and why each cannot
/// run; exit code 3).
pub fn decide_interop(mode: InteropMode, offer: &InteropOffer) -> Result<InteropDecision> {
    let decision = |route: InteropRoute, reason: String, passed_over: Vec<String>| {
        Ok(InteropDecision {
            route,
            shared: route.shared(),
            reason,
            passed_over,
        })
    };
    if mode == InteropMode::Off {
        return decision(
            InteropRoute::Host,
            "host path: interop is off".into(),
            Vec::new(),
        );
    }
    let Some(no_sharing) = sharing_missing(offer) else {
        return decision(
            InteropRoute::GlSharing,
            format!(
                "GL sharing: device '{}' reports {CL_GL_SHARING}",
                offer.device
            ),
            Vec::new(),
        );
    };
    let Some(no_external) = external_missing(offer) else {
        return decision(
            InteropRoute::ExternalMemory,
            format!(
                "external memory: device '{}' reports {CL_EXTERNAL_MEMORY_FD}, the GL context \
                 {GL_MEMORY_OBJECT_FD} and Vulkan {VK_EXTERNAL_MEMORY_FD}",
                offer.device
            ),
            vec![no_sharing],
        );
    };
    if mode == InteropMode::On {
        return Err(Error::gl_sharing_required(
            &offer.device,
            &format!("{no_sharing}; {no_external}"),
        ));
    }
    decision(
        InteropRoute::Host,
        format!("host path: {no_sharing}; {no_external}"),
        vec![no_sharing, no_external],
    )
}
