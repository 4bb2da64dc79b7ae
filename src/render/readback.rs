//! Ending a frame: resolving the multisampled image and reading colour and
//! depth back into a [`Frame`].

use glow::HasContext;

use super::programs::check;
use super::{Frame, Renderer};
use crate::error::Result;

impl Renderer {
    /// Ends the frame: resolves the multisampled image and reads back colour
    /// (RGBA8) and depth (window depth in [0, 1]), both flipped to top row first.
    pub fn finish(&mut self) -> Result<Frame> {
        self.finish_with(true)
    }

    /// [`finish`](Self::finish) without the depth: resolves and reads back
    /// the colour only, and the [`Frame`]'s `depth` is empty. For pictures
    /// that need no depth test afterwards (no SVG visibility): it saves the
    /// depth resolve, a 4-byte-per-pixel read-back and its flip.
    pub fn finish_color(&mut self) -> Result<Frame> {
        self.finish_with(false)
    }

    fn finish_with(&mut self, with_depth: bool) -> Result<Frame> {
        self.frame("finish")?;
        self.frame = None;
        let gl = &self.gl;
        let (w, h) = (self.opts.width as i32, self.opts.height as i32);
        let (wu, hu) = (self.opts.width as usize, self.opts.height as usize);
        let mut rgba = vec![0u8; wu * hu * 4];
        let mut depth = vec![0f32; if with_depth { wu * hu } else { 0 }];
        let blit = if with_depth {
            glow::COLOR_BUFFER_BIT | glow::DEPTH_BUFFER_BIT
        } else {
            glow::COLOR_BUFFER_BIT
        };
        // SAFETY: the context is current (`frame`); the destination slices hold
        // exactly w*h RGBA8 pixels and w*h floats, with PACK_ALIGNMENT 1.
        unsafe {
            if let Some(ms) = &self.ms {
                gl.bind_framebuffer(glow::READ_FRAMEBUFFER, Some(ms.fbo));
                gl.bind_framebuffer(glow::DRAW_FRAMEBUFFER, Some(self.resolve.fbo));
                // Colour is averaged over samples; depth (NEAREST is required)
                // takes one sample.
                gl.blit_framebuffer(0, 0, w, h, 0, 0, w, h, blit, glow::NEAREST);
                check(gl, "resolving the multisampled frame")?;
            }
            gl.bind_framebuffer(glow::READ_FRAMEBUFFER, Some(self.resolve.fbo));
            gl.read_buffer(glow::COLOR_ATTACHMENT0);
            gl.read_pixels(
                0,
                0,
                w,
                h,
                glow::RGBA,
                glow::UNSIGNED_BYTE,
                glow::PixelPackData::Slice(Some(&mut rgba)),
            );
            if with_depth {
                gl.read_pixels(
                    0,
                    0,
                    w,
                    h,
                    glow::DEPTH_COMPONENT,
                    glow::FLOAT,
                    glow::PixelPackData::Slice(Some(bytemuck::cast_slice_mut(&mut depth))),
                );
            }
        }
        check(gl, "reading back the frame")?;
        flip_rows(&mut rgba, wu * 4);
        flip_rows(&mut depth, wu);
        Ok(Frame {
            width: self.opts.width,
            height: self.opts.height,
            rgba,
            depth,
        })
    }
}

/// GL rows run bottom-up; images top-down. In place (no second image).
fn flip_rows<T: Copy>(data: &mut [T], row: usize) {
    let n = data.len() / row.max(1);
    for i in 0..n / 2 {
        let (top, bottom) = data.split_at_mut((n - 1 - i) * row);
        top[i * row..(i + 1) * row].swap_with_slice(&mut bottom[..row]);
    }
}
