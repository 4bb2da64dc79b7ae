//! The window: winit for events, glutin for its OpenGL context, egui (through
//! egui-winit and egui_glow) for the controls. The window's context draws
//! only the UI and the latest frame as a texture; the frames themselves are
//! drawn by the headless renderer on the compute thread ([`super::engine`]),
//! so the event loop never waits for compute and a screenshot is the image
//! the headless renderer made.

use super::NoDisplay;
use super::app::App;
use egui_glow::glow;
use glutin::context::{ContextApi, ContextAttributesBuilder, NotCurrentGlContext};
use glutin::display::{GetGlDisplay, GlDisplay};
use glutin::prelude::GlSurface;
use glutin::surface::{Surface, SwapInterval, WindowSurface};
use std::num::NonZeroU32;
use std::sync::Arc;
use winit::application::ApplicationHandler;
use winit::event::WindowEvent;
use winit::event_loop::{ActiveEventLoop, ControlFlow, EventLoop, EventLoopProxy};
use winit::raw_window_handle::HasWindowHandle;
use winit::window::{Window, WindowId};

/// What wakes the event loop: a reply of the compute thread, or egui asking
/// for a repaint.
#[derive(Debug, Clone, Copy)]
pub enum Wake {
    Reply,
    Repaint,
}

/// The window, its GL surface and context.
struct GlWindow {
    window: Window,
    context: glutin::context::PossiblyCurrentContext,
    surface: Surface<WindowSurface>,
}

/// The window with its UI, once the event loop has made it.
struct Open {
    gl: GlWindow,
    egui: egui_glow::EguiGlow,
}

/// The event-loop handler: the window (made on `resumed`) around the app.
struct Handler {
    app: App,
    open: Option<Open>,
    title: String,
    inner: [u32; 2],
    proxy: EventLoopProxy<Wake>,
    /// A failure to open the window or to draw.
    error: Option<anyhow::Error>,
    /// Paints since a capture was asked for.
    painted_for_capture: u32,
}

/// An error message of the window crates without the source file and line
/// they put before it (`os error at …/x11/mod.rs:123: …`).
fn without_source_location(msg: &str) -> String {
    match msg.rfind(".rs:") {
        Some(i) => msg[i + 4..]
            .trim_start_matches(|c: char| c.is_ascii_digit() || c == ':')
            .trim()
            .to_string(),
        None => msg.to_string(),
    }
}

/// Opens the window and runs the app until it quits (the user closes the
/// window, or the script ends).
///
/// # Errors
/// [`NoDisplay`] when there is no display to open a window on or no OpenGL
/// context for it; the app's own errors (a failed frame in a script).
pub fn run(
    app_of: impl FnOnce(EventLoopProxy<Wake>) -> anyhow::Result<App>,
    title: String,
    inner: [u32; 2],
) -> anyhow::Result<()> {
    if std::env::var_os("DISPLAY").is_none_or(|d| d.is_empty()) {
        let wayland = std::env::var_os("WAYLAND_DISPLAY").is_some();
        return Err(NoDisplay(if wayland {
            "DISPLAY is not set; the viewer needs an X11 display (XWayland on a Wayland desktop)"
                .into()
        } else {
            "DISPLAY is not set (no X11 display; run under a desktop session, or under Xvfb \
             with xvfb-run)"
                .into()
        })
        .into());
    }
    let event_loop = EventLoop::<Wake>::with_user_event().build().map_err(|e| {
        let display = std::env::var("DISPLAY").unwrap_or_default();
        NoDisplay(format!(
            "cannot connect to the X11 display {display} ({}); is an X server running there?",
            without_source_location(&e.to_string())
        ))
    })?;
    let proxy = event_loop.create_proxy();
    let app = app_of(proxy.clone())?;
    let mut h = Handler {
        app,
        open: None,
        title,
        inner,
        proxy,
        error: None,
        painted_for_capture: 0,
    };
    event_loop
        .run_app(&mut h)
        .map_err(|e| anyhow::anyhow!("the window's event loop failed: {e}"))?;
    if let Some(e) = h.error.take() {
        return Err(e);
    }
    h.app.finish()
}

/// Makes the window and its GL context (EGL, else GLX).
fn open_window(
    el: &ActiveEventLoop,
    title: &str,
    inner: [u32; 2],
) -> Result<(GlWindow, glow::Context), NoDisplay> {
    let attrs = Window::default_attributes()
        .with_title(title)
        .with_inner_size(winit::dpi::PhysicalSize::new(inner[0], inner[1]));
    let (window, config) = gl_config(el, &attrs)?;
    let display = config.display();
    let context = gl_context(&display, &config, window.as_ref())?;
    let window = match window {
        Some(w) => w,
        None => glutin_winit::finalize_window(el, attrs, &config)
            .map_err(|e| NoDisplay(format!("cannot open a window: {e}")))?,
    };
    let surface = gl_surface(&display, &config, &window)?;
    let context = context
        .make_current(&surface)
        .map_err(|e| NoDisplay(format!("cannot make the window's GL context current: {e}")))?;
    // No vsync: a script runs as fast as frames come; the UI repaints on events.
    let _ = surface.set_swap_interval(&context, SwapInterval::DontWait);
    // SAFETY: the context is current on this thread; the loader returns its
    // entry points.
    let gl = unsafe { glow::Context::from_loader_function_cstr(|s| display.get_proc_address(s)) };
    Ok((
        GlWindow {
            window,
            context,
            surface,
        },
        gl,
    ))
}

/// The display's first GL configuration for a window with `attrs`, and the
/// window if the display made it already.
fn gl_config(
    el: &ActiveEventLoop,
    attrs: &winit::window::WindowAttributes,
) -> Result<(Option<Window>, glutin::config::Config), NoDisplay> {
    let template = glutin::config::ConfigTemplateBuilder::new()
        .with_depth_size(0)
        .with_stencil_size(0)
        .with_transparency(false);
    // glutin hands the picker every matching config and wants one back; EGL
    // may match none without an error, and the picker cannot return one:
    // that case is caught here (quietly) and reported as no configuration.
    let built = {
        let hook = std::panic::take_hook();
        std::panic::set_hook(Box::new(|_| {}));
        let r = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
            glutin_winit::DisplayBuilder::new()
                .with_preference(glutin_winit::ApiPreference::FallbackEgl)
                .with_window_attributes(Some(attrs.clone()))
                .build(el, template, |mut configs| {
                    configs.next().expect("at least one config")
                })
                .map_err(|e| e.to_string())
        }));
        std::panic::set_hook(hook);
        r.unwrap_or_else(|_| Err("the display offers no matching configuration".into()))
    };
    built.map_err(|e| NoDisplay(format!("no OpenGL configuration for a window: {e}")))
}

/// A desktop GL context for `config` (GLES if that fails), not yet current.
fn gl_context(
    display: &glutin::display::Display,
    config: &glutin::config::Config,
    window: Option<&Window>,
) -> Result<glutin::context::NotCurrentContext, NoDisplay> {
    let handle = window
        .and_then(|w| w.window_handle().ok())
        .map(|h| h.as_raw());
    let desktop = ContextAttributesBuilder::new().build(handle);
    let gles = ContextAttributesBuilder::new()
        .with_context_api(ContextApi::Gles(None))
        .build(handle);
    // SAFETY: the config and the raw window handle come from this display
    // and this event loop, and outlive the call.
    unsafe { display.create_context(config, &desktop) }
        .or_else(|_| unsafe { display.create_context(config, &gles) })
        .map_err(|e| NoDisplay(format!("cannot create an OpenGL context for a window: {e}")))
}

/// The GL surface of `window`, at its inner size.
fn gl_surface(
    display: &glutin::display::Display,
    config: &glutin::config::Config,
    window: &Window,
) -> Result<Surface<WindowSurface>, NoDisplay> {
    let size = window.inner_size();
    let nz = |v: u32| NonZeroU32::new(v).unwrap_or(NonZeroU32::MIN);
    let raw = window
        .window_handle()
        .map_err(|e| NoDisplay(format!("the window has no handle: {e}")))?
        .as_raw();
    let sattrs = glutin::surface::SurfaceAttributesBuilder::<WindowSurface>::new().build(
        raw,
        nz(size.width),
        nz(size.height),
    );
    // SAFETY: the surface is made for this window, which the GlWindow keeps
    // alive (and drops after the surface).
    unsafe { display.create_window_surface(config, &sattrs) }
        .map_err(|e| NoDisplay(format!("cannot make a GL surface for the window: {e}")))
}

impl Handler {
    fn fail(&mut self, el: &ActiveEventLoop, e: anyhow::Error) {
        if self.error.is_none() {
            self.error = Some(e);
        }
        el.exit();
    }

    fn redraw(&mut self, el: &ActiveEventLoop) {
        let Some(open) = self.open.as_mut() else {
            return;
        };
        let app = &mut self.app;
        open.egui.run(&open.gl.window, |ui| app.ui(ui));
        // SAFETY: plain GL state calls on the window's current context.
        unsafe {
            use glow::HasContext;
            let gl = open.egui.painter.gl();
            gl.clear_color(0.12, 0.12, 0.12, 1.0);
            gl.clear(glow::COLOR_BUFFER_BIT);
        }
        open.egui.paint(&open.gl.window);
        // egui lays a new overlay out on its first frame unseen: a capture
        // waits for a second paint.
        self.painted_for_capture += u32::from(self.app.capture.is_some());
        if self.painted_for_capture >= 2
            && let Some(path) = self.app.capture.take()
        {
            self.painted_for_capture = 0;
            let size = open.gl.window.inner_size();
            let r = save_window(open.egui.painter.gl(), size.width, size.height, &path);
            match r {
                Ok(()) => println!("wrote {}", path.display()),
                Err(e) => return self.fail(el, e),
            }
        }
        if let Err(e) = open.gl.surface.swap_buffers(&open.gl.context) {
            let e = anyhow::anyhow!("the window's buffers could not be swapped: {e}");
            self.fail(el, e);
            return;
        }
        match self.app.step() {
            Ok(true) => {}
            Ok(false) => el.exit(),
            Err(e) => self.fail(el, e),
        }
        if self.app.wants_frames()
            && let Some(o) = self.open.as_ref()
        {
            o.gl.window.request_redraw();
        }
        el.set_control_flow(match self.app.play_period() {
            Some(p) => ControlFlow::WaitUntil(std::time::Instant::now() + p),
            None => ControlFlow::Wait,
        });
    }
}

impl ApplicationHandler<Wake> for Handler {
    fn resumed(&mut self, el: &ActiveEventLoop) {
        if self.open.is_some() {
            return;
        }
        let (gl, glow_ctx) = match open_window(el, &self.title, self.inner) {
            Ok(w) => w,
            Err(e) => return self.fail(el, e.into()),
        };
        let glow_ctx = Arc::new(glow_ctx);
        // EguiGlow::new panics if its painter cannot be made: try one first.
        match egui_glow::Painter::new(glow_ctx.clone(), "", None, false) {
            Ok(mut p) => p.destroy(),
            Err(e) => {
                let e = NoDisplay(format!("the window's OpenGL cannot draw the controls: {e}"));
                return self.fail(el, e.into());
            }
        }
        let egui = egui_glow::EguiGlow::new(el, glow_ctx, None, None, false);
        let proxy = self.proxy.clone();
        egui.egui_ctx.set_request_repaint_callback(move |_| {
            let _ = proxy.send_event(Wake::Repaint);
        });
        gl.window.request_redraw();
        self.open = Some(Open { gl, egui });
        el.set_control_flow(ControlFlow::Wait);
    }

    fn window_event(&mut self, el: &ActiveEventLoop, _id: WindowId, event: WindowEvent) {
        let Some(open) = self.open.as_mut() else {
            return;
        };
        match &event {
            WindowEvent::CloseRequested | WindowEvent::Destroyed => {
                el.exit();
                return;
            }
            WindowEvent::RedrawRequested => {
                self.redraw(el);
                return;
            }
            WindowEvent::Resized(s) => {
                let nz = |v: u32| NonZeroU32::new(v).unwrap_or(NonZeroU32::MIN);
                open.gl
                    .surface
                    .resize(&open.gl.context, nz(s.width), nz(s.height));
            }
            _ => {}
        }
        let r = open.egui.on_window_event(&open.gl.window, &event);
        if r.repaint {
            open.gl.window.request_redraw();
        }
    }

    fn new_events(&mut self, _el: &ActiveEventLoop, cause: winit::event::StartCause) {
        // The animation's next step is due.
        if matches!(cause, winit::event::StartCause::ResumeTimeReached { .. })
            && let Some(o) = &self.open
        {
            o.gl.window.request_redraw();
        }
    }

    fn user_event(&mut self, _el: &ActiveEventLoop, _wake: Wake) {
        if let Some(o) = &self.open {
            o.gl.window.request_redraw();
        }
    }

    fn exiting(&mut self, _el: &ActiveEventLoop) {
        if let Some(o) = self.open.as_mut() {
            o.egui.destroy();
        }
    }
}

/// Reads the painted back buffer and saves it as PNG (rows flipped: GL's
/// first row is the bottom one).
fn save_window(gl: &glow::Context, w: u32, h: u32, path: &std::path::Path) -> anyhow::Result<()> {
    use glow::HasContext;
    let mut rgba = vec![0u8; w as usize * h as usize * 4];
    // SAFETY: the buffer holds w × h RGBA8 pixels, what the call writes.
    unsafe {
        gl.pixel_store_i32(glow::PACK_ALIGNMENT, 1);
        gl.read_pixels(
            0,
            0,
            w as i32,
            h as i32,
            glow::RGBA,
            glow::UNSIGNED_BYTE,
            glow::PixelPackData::Slice(Some(&mut rgba)),
        );
    }
    let row = w as usize * 4;
    let mut flipped: Vec<u8> = rgba
        .chunks_exact(row.max(1))
        .rev()
        .flatten()
        .copied()
        .collect();
    // The window is opaque whatever alpha its buffer kept.
    flipped.iter_mut().skip(3).step_by(4).for_each(|a| *a = 255);
    let frame = shapecue::render::Frame {
        width: w,
        height: h,
        rgba: flipped,
        depth: Vec::new(),
    };
    frame.save_png(path)?;
    Ok(())
}

#[cfg(test)]
mod tests {
    #[test]
    fn window_errors_lose_their_source_location() {
        let m = "os error at /root/.cargo/registry/src/x/winit-0.30.12/src/platform_impl/linux/x11/mod.rs:123: failed to open display";
        assert_eq!(super::without_source_location(m), "failed to open display");
        assert_eq!(super::without_source_location("no display"), "no display");
    }
}
