//! Flat primitives already in clip space (the edge stage's quads and cap
//! triangles), and world-space lines drawn as screen-aligned quads.

use glow::HasContext;

use super::programs::check;
use super::{Renderer, segments_to_clip_quads};
use crate::error::{Error, Result};

impl Renderer {
    /// Draws clip-space quads, 4 vertices each, in House & Li's edge-out order:
    /// `0 = s0 − p, 1 = s1 − p, 2 = s1 + p, 3 = s0 + p` (s0, s1 the edge ends,
    /// p the screen-space perpendicular), i.e. **around the quad's perimeter**,
    /// not in triangle-strip order. Each quad is drawn as the triangles 0-1-2
    /// and 0-2-3, so any convex quad in perimeter order works, and so does the
    /// adjacency cap layout (middle vector, p0, sM, p1). Winding does not matter.
    ///
    /// A quad whose first vertex has a NaN x (House & Li's non-drawable marker
    /// `(NaN, 0, −1, 1)`), or that has any non-finite coordinate, is skipped on
    /// the CPU, so nothing of it reaches the rasteriser. McGuire & Hughes' marker
    /// `(0, 0, −1, 1)` on all four vertices is a zero-area quad and draws nothing.
    ///
    /// Flat `color` (alpha-blended when its alpha is < 1), depth-tested with ≤
    /// and written to depth.
    pub fn draw_clip_quads(&mut self, verts: &[[f32; 4]], color: [f32; 4]) -> Result<()> {
        self.draw_clip(verts, 4, color, "draw_clip_quads")
    }

    /// Draws clip-space triangles, 3 vertices each (McGuire & Hughes half-caps:
    /// `s`, `s + p·sign(m·p)`, `s + m`); skipping, colour and depth as in
    /// [`draw_clip_quads`](Self::draw_clip_quads), with the NaN test on each
    /// triangle's first vertex. Adjacency caps (4 per cap) go to `draw_clip_quads`.
    pub fn draw_clip_triangles(&mut self, verts: &[[f32; 4]], color: [f32; 4]) -> Result<()> {
        self.draw_clip(verts, 3, color, "draw_clip_triangles")
    }

    /// Draws world-space segments (consecutive point pairs) as screen-aligned
    /// quads `width_px` pixels wide with square ends, through
    /// [`segments_to_clip_quads`] and [`draw_clip_quads`](Self::draw_clip_quads).
    pub fn draw_lines(
        &mut self,
        segments: &[[f32; 3]],
        color: [f32; 4],
        width_px: f32,
    ) -> Result<()> {
        let ok = segments.len().is_multiple_of(2) && width_px.is_finite() && width_px > 0.0;
        if !ok {
            return Err(Error::InvalidArgument(format!(
                "draw_lines: needs an even number of points (got {}) and a positive width (got {width_px})",
                segments.len()
            )));
        }
        let view_proj = self.frame("draw_lines")?.view.view_proj;
        let quads = segments_to_clip_quads(
            view_proj,
            [self.opts.width, self.opts.height],
            segments,
            width_px,
        );
        self.draw_clip(&quads, 4, color, "draw_lines")
    }

    fn draw_clip(
        &mut self,
        verts: &[[f32; 4]],
        per: usize,
        color: [f32; 4],
        what: &str,
    ) -> Result<()> {
        if !verts.len().is_multiple_of(per) {
            return Err(Error::InvalidArgument(format!(
                "{what}: {} vertices is not a multiple of {per}",
                verts.len()
            )));
        }
        self.frame(what)?;
        // Compact the drawable primitives so that the marker vertices never
        // reach the GPU: what llvmpipe (or any driver) does with NaN positions
        // is undefined. Buffers that hold only drawable primitives (the edge
        // stage's compacted read-back) go to GL as they are.
        let drawable = |prim: &[[f32; 4]]| {
            !prim[0][0].is_nan() && prim.iter().flatten().all(|c| c.is_finite())
        };
        let compacted: Vec<[f32; 4]>;
        let kept: &[[f32; 4]] = if verts.chunks_exact(per).all(drawable) {
            verts
        } else {
            compacted = verts
                .chunks_exact(per)
                .filter(|p| drawable(p))
                .flatten()
                .copied()
                .collect();
            &compacted
        };
        if kept.is_empty() {
            return Ok(());
        }
        let prims = kept.len() / per;
        // Quads are drawn as two triangles through the shared index pattern
        // 0 1 2 0 2 3 (grown when needed), triangles as they are.
        let index_count = if per == 4 { prims * 6 } else { prims * 3 };
        if u32::try_from(kept.len()).is_err() || i32::try_from(index_count).is_err() {
            return Err(Error::InvalidArgument(format!(
                "{what}: {prims} primitives are too many for one draw"
            )));
        }
        let quads = if per == 4 { prims } else { 0 };
        // SAFETY: the context is current (`frame`); clip_vao is this
        // renderer's own clip-vertex array.
        unsafe { self.clip_state(self.clip_vao, color, quads) };
        let gl = &self.gl;
        // SAFETY: the context is current (`frame`); every index of the
        // pattern's first `index_count` is < 4 * prims = kept.len().
        unsafe {
            gl.bind_buffer(glow::ARRAY_BUFFER, Some(self.clip_bufs[0]));
            gl.buffer_data_u8_slice(
                glow::ARRAY_BUFFER,
                bytemuck::cast_slice(kept),
                glow::STREAM_DRAW,
            );
            if per == 4 {
                gl.draw_elements(glow::TRIANGLES, index_count as i32, glow::UNSIGNED_INT, 0);
            } else {
                gl.draw_arrays(glow::TRIANGLES, 0, index_count as i32);
            }
            self.clip_done();
        }
        check(gl, &format!("{what} ({prims} primitives)"))
    }

    /// Binds the clip program with `color` and the vertex array `vao`, grows
    /// the quad index pattern that every clip-vertex array shares (0 1 2 0 2 3
    /// per quad, at least doubled when it grows, so that the uploads of a
    /// growing edge count stay rare) to cover `quads` quads, turns blending on
    /// for a color with alpha below 1, and sets the depth test against the
    /// surface without writing depth: the depth buffer keeps only the
    /// surfaces, so that the SVG visibility test (`visibility.rs`) sees a
    /// line hidden by the surface and never by another line's wide quad.
    /// [`Renderer::clip_done`] turns depth writes back on.
    ///
    /// # Safety
    /// The context must be current and `vao` one of this renderer's
    /// clip-vertex arrays (bound to the shared element buffer).
    pub(super) unsafe fn clip_state(
        &mut self,
        vao: glow::VertexArray,
        color: [f32; 4],
        quads: usize,
    ) {
        let gl = &self.gl;
        let [r, g, b, a] = color;
        // SAFETY: the caller's contract.
        unsafe {
            gl.use_program(Some(self.clip_prog));
            gl.uniform_4_f32(self.clip_color.as_ref(), r, g, b, a);
            gl.bind_vertex_array(Some(vao));
            if quads > self.quad_pattern {
                let quads = quads.max(2 * self.quad_pattern).min(u32::MAX as usize / 4);
                let pattern: Vec<u32> = (0..quads as u32)
                    .flat_map(|q| [0, 1, 2, 0, 2, 3].map(|k| 4 * q + k))
                    .collect();
                gl.buffer_data_u8_slice(
                    glow::ELEMENT_ARRAY_BUFFER,
                    bytemuck::cast_slice(&pattern),
                    glow::STATIC_DRAW,
                );
                self.quad_pattern = quads;
            }
            if a < 1.0 {
                gl.enable(glow::BLEND);
            } else {
                gl.disable(glow::BLEND);
            }
            gl.depth_func(glow::LEQUAL);
            gl.depth_mask(false);
        }
    }

    /// Undoes what [`Renderer::clip_state`] changed that later surface draws
    /// rely on: depth writes on, no vertex array bound.
    ///
    /// # Safety
    /// The context must be current.
    pub(super) unsafe fn clip_done(&self) {
        // SAFETY: the caller's contract.
        unsafe {
            self.gl.depth_mask(true);
            self.gl.bind_vertex_array(None);
        }
    }
}
