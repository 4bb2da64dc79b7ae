//! The renderer's framebuffers (colour and depth renderbuffers, multisampled
//! and resolve) and the checks of image size and samples against the driver.

use glow::HasContext;

use super::RenderOptions;
use super::programs::check;
use crate::error::{Error, Result};

/// A framebuffer object with a colour and a depth renderbuffer.
pub(super) struct Target {
    pub(super) fbo: glow::NativeFramebuffer,
    pub(super) renderbuffers: [glow::NativeRenderbuffer; 2],
}

impl Target {
    /// Frees the framebuffer and its renderbuffers.
    ///
    /// # Safety
    /// The context of `gl` (the one that made the target) must be current.
    pub(super) unsafe fn delete(self, gl: &glow::Context) {
        unsafe {
            gl.delete_framebuffer(self.fbo);
            for rb in self.renderbuffers {
                gl.delete_renderbuffer(rb);
            }
        }
    }
}

/// Creates a framebuffer with RGBA8 colour and 32-bit float depth
/// renderbuffers (`samples == 0`: single-sampled) and checks completeness.
///
/// # Safety
/// The context of `gl` must be current.
pub(super) unsafe fn target(gl: &glow::Context, w: i32, h: i32, samples: i32) -> Result<Target> {
    unsafe {
        let fbo = gl
            .create_framebuffer()
            .map_err(|e| Error::render("glGenFramebuffers", e))?;
        gl.bind_framebuffer(glow::FRAMEBUFFER, Some(fbo));
        let mut renderbuffers = Vec::with_capacity(2);
        for (format, attachment) in [
            (glow::RGBA8, glow::COLOR_ATTACHMENT0),
            (glow::DEPTH_COMPONENT32F, glow::DEPTH_ATTACHMENT),
        ] {
            let rb = gl
                .create_renderbuffer()
                .map_err(|e| Error::render("glGenRenderbuffers", e))?;
            gl.bind_renderbuffer(glow::RENDERBUFFER, Some(rb));
            if samples > 0 {
                gl.renderbuffer_storage_multisample(glow::RENDERBUFFER, samples, format, w, h);
            } else {
                gl.renderbuffer_storage(glow::RENDERBUFFER, format, w, h);
            }
            gl.framebuffer_renderbuffer(
                glow::FRAMEBUFFER,
                attachment,
                glow::RENDERBUFFER,
                Some(rb),
            );
            renderbuffers.push(rb);
        }
        let renderbuffers = [renderbuffers[0], renderbuffers[1]];
        let made = Target { fbo, renderbuffers };
        if let Err(e) = check(
            gl,
            &format!("allocating a {w}x{h} framebuffer with {samples} samples"),
        ) {
            made.delete(gl);
            return Err(e);
        }
        let status = gl.check_framebuffer_status(glow::FRAMEBUFFER);
        if status != glow::FRAMEBUFFER_COMPLETE {
            made.delete(gl);
            return Err(Error::render(
                format!("framebuffer {w}x{h}, {samples} samples"),
                format!("incomplete (status 0x{status:04X})"),
            ));
        }
        Ok(made)
    }
}

/// Checks `opts` against the driver's sample and size limits.
pub(super) fn check_limits(
    opts: &RenderOptions,
    driver: &str,
    max_samples: i32,
    max_size: i32,
) -> Result<()> {
    if opts.msaa as i32 > max_samples {
        return Err(Error::InvalidArgument(format!(
            "msaa {} exceeds the {max_samples} samples '{driver}' supports",
            opts.msaa
        )));
    }
    if opts.width as i64 > max_size as i64 || opts.height as i64 > max_size as i64 {
        return Err(Error::InvalidArgument(format!(
            "render size {}x{} exceeds the {max_size}x{max_size} '{driver}' supports",
            opts.width, opts.height
        )));
    }
    Ok(())
}

/// Checks what [`Renderer::new`](super::Renderer::new) and
/// [`Renderer::reconfigure`](super::Renderer::reconfigure) can check
/// before touching GL.
pub(super) fn check_options(opts: &RenderOptions) -> Result<()> {
    if opts.width == 0 || opts.height == 0 {
        return Err(Error::InvalidArgument(format!(
            "render size {}x{} must be at least 1x1",
            opts.width, opts.height
        )));
    }
    if ![0, 2, 4, 8].contains(&opts.msaa) {
        return Err(Error::InvalidArgument(format!(
            "msaa {} must be 0, 2, 4 or 8",
            opts.msaa
        )));
    }
    Ok(())
}

/// The multisampled (when `msaa > 0`) and resolve targets of `opts`, and the
/// samples the driver gave the first (drivers may round up: llvmpipe 2 → 4).
///
/// # Safety
/// The context of `gl` must be current.
pub(super) unsafe fn targets(
    gl: &glow::Context,
    opts: &RenderOptions,
) -> Result<(Option<Target>, Target, i32)> {
    let (w, h) = (opts.width as i32, opts.height as i32);
    unsafe {
        let ms = if opts.msaa > 0 {
            Some(target(gl, w, h, opts.msaa as i32)?)
        } else {
            None
        };
        let resolve = match target(gl, w, h, 0) {
            Ok(t) => t,
            Err(e) => {
                if let Some(t) = ms {
                    t.delete(gl);
                }
                return Err(e);
            }
        };
        let samples = match &ms {
            Some(t) => {
                gl.bind_framebuffer(glow::FRAMEBUFFER, Some(t.fbo));
                gl.get_parameter_i32(glow::SAMPLES)
            }
            None => 0,
        };
        gl.viewport(0, 0, w, h);
        Ok((ms, resolve, samples))
    }
}
