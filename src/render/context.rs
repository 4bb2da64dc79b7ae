//! Headless OpenGL through EGL: one process-wide EGL display, one GL context
//! per [`Renderer`](super::Renderer).
//!
//! libEGL is loaded at run time (`khronos-egl`'s `dynamic` feature), so the
//! library and the CLI start on machines without it and only rendering fails,
//! with [`Error::NoGl`] naming the packages to install.
//!
//! Display: Mesa's surfaceless platform (`EGL_MESA_platform_surfaceless`,
//! llvmpipe when no GPU is present) when the client offers it, else the default
//! display. The display is initialised once and never terminated: on EGL,
//! `eglTerminate` is not reference-counted and would pull the display from
//! under every other renderer of the process (other test threads included).
//! Contexts are made current without a surface when the display has
//! `EGL_KHR_surfaceless_context`, else on a private 1×1 pbuffer; all drawing
//! goes to the renderer's own framebuffer objects either way.

use std::ffi::c_void;
use std::sync::{Mutex, OnceLock};

use khronos_egl as egl;

use crate::error::{Error, Result};

/// `EGL_PLATFORM_SURFACELESS_MESA` (EGL_MESA_platform_surfaceless).
const PLATFORM_SURFACELESS_MESA: egl::Enum = 0x31DD;

type Egl = egl::DynamicInstance<egl::EGL1_4>;

/// The process-wide EGL state: the loaded library, the initialised display
/// and the config every context is created with.
struct Shared {
    egl: Egl,
    display: egl::Display,
    config: egl::Config,
    /// Contexts can be current without a surface.
    surfaceless_context: bool,
    /// How the display was obtained, for [`GlContext::describe`].
    platform: &'static str,
}

// SAFETY: EGL display and config handles are process-wide values that the EGL
// spec allows any thread to use; `Shared` is only read after initialisation.
unsafe impl Send for Shared {}
// SAFETY: as above; no interior mutability.
unsafe impl Sync for Shared {}

static SHARED: OnceLock<std::result::Result<Shared, String>> = OnceLock::new();

/// Serialises context creation and destruction: cheap, and it keeps Mesa's
/// display-level bookkeeping out of races when test threads start together.
static CREATE_LOCK: Mutex<()> = Mutex::new(());

fn lock() -> std::sync::MutexGuard<'static, ()> {
    // A panic while holding the lock leaves no EGL state half-built that a
    // later caller could trip on, so a poisoned lock is still usable.
    CREATE_LOCK.lock().unwrap_or_else(|e| e.into_inner())
}

fn has_ext(list: Option<&std::ffi::CStr>, name: &str) -> bool {
    list.map(|l| l.to_string_lossy().split_whitespace().any(|e| e == name))
        .unwrap_or(false)
}

fn init_shared() -> std::result::Result<Shared, String> {
    // SAFETY: loads the system's libEGL, which implements the EGL API.
    let egl = unsafe { Egl::load_required() }
        .map_err(|e| format!("cannot load libEGL.so.1 (EGL ≥ 1.4): {e}"))?;
    let client_ext = egl.query_string(None, egl::EXTENSIONS).ok();

    let mut display = None;
    let mut platform = "default display";
    if has_ext(client_ext, "EGL_MESA_platform_surfaceless")
        && let Some(egl15) = egl.upcast::<egl::EGL1_5>()
        // SAFETY: the surfaceless platform takes no native display (EGL_DEFAULT_DISPLAY).
        && let Ok(d) = unsafe {
            egl15.get_platform_display(
                PLATFORM_SURFACELESS_MESA,
                egl::DEFAULT_DISPLAY,
                &[egl::ATTRIB_NONE],
            )
        }
        && egl.initialize(d).is_ok()
    {
        display = Some(d);
        platform = "surfaceless platform";
    }
    let display = match display {
        Some(d) => d,
        None => {
            // SAFETY: EGL_DEFAULT_DISPLAY is always a valid argument.
            let d = unsafe { egl.get_display(egl::DEFAULT_DISPLAY) }
                .ok_or("eglGetDisplay found no display")?;
            egl.initialize(d).map_err(|e| {
                format!(
                    "eglInitialize of the default display failed ({e}); EGL offers no \
                     surfaceless platform, and the default one may need a display server"
                )
            })?;
            d
        }
    };

    let display_ext = egl.query_string(Some(display), egl::EXTENSIONS).ok();
    let surfaceless_context = has_ext(display_ext, "EGL_KHR_surfaceless_context");
    // We draw into our own FBOs, so the config only has to support desktop GL
    // (and a pbuffer when contexts cannot be surfaceless).
    let surface_type = if surfaceless_context {
        0
    } else {
        egl::PBUFFER_BIT
    };
    let attribs = [
        egl::RENDERABLE_TYPE,
        egl::OPENGL_BIT,
        egl::SURFACE_TYPE,
        surface_type,
        egl::NONE,
    ];
    let config = egl
        .choose_first_config(display, &attribs)
        .map_err(|e| format!("eglChooseConfig failed: {e}"))?
        .ok_or("EGL offers no desktop-OpenGL config (is Mesa's libgl1-mesa-dri installed?)")?;
    Ok(Shared {
        egl,
        display,
        config,
        surfaceless_context,
        platform,
    })
}

fn shared() -> Result<&'static Shared> {
    SHARED
        .get_or_init(init_shared)
        .as_ref()
        .map_err(|detail| Error::NoGl {
            detail: detail.clone(),
        })
}

/// One GL context (and its pbuffer, if the display needs one). Not `Send`:
/// a GL context is current on one thread, and [`GlContext::make_current`]
/// would fail on another thread while it is still current here.
pub(crate) struct GlContext {
    shared: &'static Shared,
    context: egl::Context,
    surface: Option<egl::Surface>,
    _not_send: std::marker::PhantomData<*const ()>,
}

impl GlContext {
    /// Creates a GL ≥ 3.3 core-profile context, makes it current on this
    /// thread and loads the GL entry points.
    pub(crate) fn new() -> Result<(GlContext, glow::Context)> {
        let shared = shared()?;
        let egl = &shared.egl;
        let _guard = lock();
        egl.bind_api(egl::OPENGL_API).map_err(|e| Error::NoGl {
            detail: format!("eglBindAPI(OpenGL) failed: {e}"),
        })?;
        // Asking for 3.3 core gets the highest core version the driver has
        // (4.5 on llvmpipe); 3.3 is all the shaders need.
        let attribs = [
            egl::CONTEXT_MAJOR_VERSION,
            3,
            egl::CONTEXT_MINOR_VERSION,
            3,
            egl::CONTEXT_OPENGL_PROFILE_MASK,
            egl::CONTEXT_OPENGL_CORE_PROFILE_BIT,
            egl::NONE,
        ];
        let context = egl
            .create_context(shared.display, shared.config, None, &attribs)
            .map_err(|e| Error::NoGl {
                detail: format!("cannot create an OpenGL 3.3 core context: {e}"),
            })?;
        let surface = if shared.surfaceless_context {
            None
        } else {
            let attribs = [egl::WIDTH, 1, egl::HEIGHT, 1, egl::NONE];
            match egl.create_pbuffer_surface(shared.display, shared.config, &attribs) {
                Ok(s) => Some(s),
                Err(e) => {
                    let _ = egl.destroy_context(shared.display, context);
                    return Err(Error::render("eglCreatePbufferSurface (1x1)", e));
                }
            }
        };
        let ctx = GlContext {
            shared,
            context,
            surface,
            _not_send: std::marker::PhantomData,
        };
        ctx.make_current()?;
        // SAFETY: the context is current on this thread, so glow's GL_VERSION
        // query and the loaded entry points refer to it.
        let gl = unsafe {
            glow::Context::from_loader_function(|name| {
                egl.get_proc_address(name)
                    .map_or(std::ptr::null(), |f| f as *const c_void)
            })
        };
        Ok((ctx, gl))
    }

    /// Makes this context current on the calling thread, unless it already is
    /// (several renderers on one thread take turns).
    pub(crate) fn make_current(&self) -> Result<()> {
        let egl = &self.shared.egl;
        if egl.get_current_context() == Some(self.context) {
            return Ok(());
        }
        // eglBindAPI is per-thread state; make sure this thread binds desktop GL.
        egl.bind_api(egl::OPENGL_API)
            .map_err(|e| Error::render("eglBindAPI(OpenGL)", e))?;
        egl.make_current(
            self.shared.display,
            self.surface,
            self.surface,
            Some(self.context),
        )
        .map_err(|e| Error::render("eglMakeCurrent", e))
    }

    /// The address of a GL entry point that glow does not load
    /// (`eglGetProcAddress`; null when EGL has none), for the extension
    /// functions of `render::external`. Callers check the extension string
    /// first: Mesa returns a stub for any name.
    pub(crate) fn proc_address(&self, name: &str) -> *const c_void {
        self.shared
            .egl
            .get_proc_address(name)
            .map_or(std::ptr::null(), |f| f as *const c_void)
    }

    /// EGL version, vendor and platform, for [`Renderer::gl_info`](super::Renderer::gl_info).
    pub(crate) fn describe(&self) -> String {
        let egl = &self.shared.egl;
        let q = |name| {
            egl.query_string(Some(self.shared.display), name)
                .map(|s| s.to_string_lossy().into_owned())
                .unwrap_or_else(|_| "?".into())
        };
        format!(
            "EGL {} ({}, {}{})",
            q(egl::VERSION),
            q(egl::VENDOR),
            self.shared.platform,
            if self.surface.is_some() {
                ", 1x1 pbuffer"
            } else {
                ", surfaceless context"
            }
        )
    }
}

impl Drop for GlContext {
    fn drop(&mut self) {
        let egl = &self.shared.egl;
        let display = self.shared.display;
        let _guard = lock();
        if egl.get_current_context() == Some(self.context) {
            // Errors cannot be reported from drop; a failure here leaks at most
            // this context, which the process-wide display still owns.
            let _ = egl.make_current(display, None, None, None);
        }
        let _ = egl.destroy_context(display, self.context);
        if let Some(s) = self.surface {
            let _ = egl.destroy_surface(display, s);
        }
    }
}
