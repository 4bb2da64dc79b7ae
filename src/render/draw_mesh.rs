//! Shaded meshes: uploads of the faces (once per topology) and of a pose
//! (once per pose), and drawing what was uploaded.

use glam::Vec3;
use glow::HasContext;

use super::programs::check;
use super::{Light, MeshStyle, Renderer};
use crate::error::{Error, Result};

impl Renderer {
    /// Draws a triangle mesh with Lambert shading (see [`MeshStyle`]).
    /// `normals` has one entry per position; `colors` one per position, or is
    /// empty to use `style.color`. Faces may have either orientation (no
    /// culling, two-sided lighting). The mesh is drawn with a polygon offset so
    /// that edges and lines drawn on it afterwards stay visible.
    ///
    /// This uploads the faces and the pose on every call; a caller drawing
    /// one mesh in many views uploads them once ([`upload_topology`],
    /// [`upload_pose`]) and calls [`draw_uploaded`] per view.
    ///
    /// [`upload_topology`]: Self::upload_topology
    /// [`upload_pose`]: Self::upload_pose
    /// [`draw_uploaded`]: Self::draw_uploaded
    pub fn draw_mesh(
        &mut self,
        positions: &[[f32; 3]],
        normals: &[[f32; 3]],
        colors: &[[f32; 3]],
        faces: &[[u32; 3]],
        style: MeshStyle,
    ) -> Result<()> {
        self.frame("draw_mesh")?;
        self.upload_pose(positions, normals, colors)?;
        self.upload_topology(faces)?;
        self.draw_uploaded(style)
    }

    /// Uploads a mesh's faces (the index buffer), kept until the next call:
    /// once per topology. Needs no frame in progress. Indices are checked
    /// against the pose when drawing.
    ///
    /// # Errors
    /// [`Error::InvalidArgument`] for more faces than one draw can take.
    pub fn upload_topology(&mut self, faces: &[[u32; 3]]) -> Result<()> {
        if i32::try_from(faces.len() * 3).is_err() {
            return Err(Error::InvalidArgument(format!(
                "draw_mesh: {} faces are too many for one draw",
                faces.len()
            )));
        }
        let max_index = faces.iter().flatten().copied().max();
        self.ctx.make_current()?;
        self.held.faces = None;
        let gl = &self.gl;
        // SAFETY: the context is current (above); the index buffer is the
        // mesh VAO's element buffer, bound with the VAO.
        unsafe {
            gl.bind_vertex_array(Some(self.mesh_vao));
            gl.buffer_data_u8_slice(
                glow::ELEMENT_ARRAY_BUFFER,
                bytemuck::cast_slice(faces),
                glow::STATIC_DRAW,
            );
            gl.bind_vertex_array(None);
        }
        check(gl, &format!("uploading {} faces", faces.len()))?;
        self.held.faces = Some((faces.len(), max_index));
        self.uploads.topology += 1;
        Ok(())
    }

    /// Uploads a pose: positions, one normal per position, and one colour
    /// per position or none (the style's flat colour); kept until the next
    /// call: once per pose. Needs no frame in progress.
    ///
    /// # Errors
    /// [`Error::InvalidArgument`] for mismatched lengths or a non-finite
    /// position (named by its index).
    pub fn upload_pose(
        &mut self,
        positions: &[[f32; 3]],
        normals: &[[f32; 3]],
        colors: &[[f32; 3]],
    ) -> Result<()> {
        let n = positions.len();
        if normals.len() != n || !(colors.is_empty() || colors.len() == n) {
            return Err(Error::InvalidArgument(format!(
                "draw_mesh: {n} positions need {n} normals (got {}) and {n} or 0 colours (got {})",
                normals.len(),
                colors.len()
            )));
        }
        if let Some(i) = positions
            .iter()
            .position(|p| !p.iter().all(|c| c.is_finite()))
        {
            let [x, y, z] = positions[i];
            return Err(Error::InvalidArgument(format!(
                "draw_mesh: vertex {i} has a non-finite position ({x}, {y}, {z})"
            )));
        }
        self.ctx.make_current()?;
        self.held.pose = None;
        let gl = &self.gl;
        let data: [&[u8]; 3] = [
            bytemuck::cast_slice(positions),
            bytemuck::cast_slice(normals),
            bytemuck::cast_slice(colors),
        ];
        // SAFETY: the context is current (above); the buffers are the mesh
        // VAO's attribute buffers.
        unsafe {
            for (b, d) in self.mesh_bufs[..3].iter().zip(data) {
                gl.bind_buffer(glow::ARRAY_BUFFER, Some(*b));
                gl.buffer_data_u8_slice(glow::ARRAY_BUFFER, d, glow::DYNAMIC_DRAW);
            }
            gl.bind_buffer(glow::ARRAY_BUFFER, None);
        }
        check(gl, &format!("uploading a pose of {n} vertices"))?;
        self.held.pose = Some((n, !colors.is_empty()));
        self.uploads.pose += 1;
        Ok(())
    }

    /// Draws the mesh last uploaded ([`upload_topology`](Self::upload_topology),
    /// [`upload_pose`](Self::upload_pose)) into the frame in progress, shaded
    /// as [`draw_mesh`](Self::draw_mesh) describes.
    ///
    /// # Errors
    /// [`Error::InvalidArgument`] outside a frame, with nothing uploaded, or
    /// when a face indexes past the uploaded vertices.
    pub fn draw_uploaded(&mut self, style: MeshStyle) -> Result<()> {
        let f = self.frame("draw_mesh")?;
        let (Some((faces, max_index)), Some((n, colored))) = (self.held.faces, self.held.pose)
        else {
            return Err(Error::InvalidArgument(
                "draw_mesh: no mesh uploaded (faces and a pose)".into(),
            ));
        };
        if let Some(m) = max_index.filter(|&m| m as usize >= n) {
            return Err(Error::InvalidArgument(format!(
                "draw_mesh: a face uses vertex {m}, past the {n} vertices"
            )));
        }
        let (light_dir, headlight) = match style.light {
            Light::Headlight => (Vec3::Z, true),
            Light::Directional(d) => (d.try_normalize().unwrap_or(Vec3::Z), false),
        };
        let cam = &f.view;
        let view_dir = cam.unit_dir();
        let gl = &self.gl;
        let u = &self.mesh_u;
        // SAFETY: the context is current (`frame`); the buffers hold `n`
        // vertices and every index is < n (checked above).
        unsafe {
            gl.use_program(Some(self.mesh_prog));
            gl.uniform_matrix_4_f32_slice(
                u.view_proj.as_ref(),
                false,
                &cam.view_proj.to_cols_array(),
            );
            gl.uniform_3_f32(u.eye.as_ref(), cam.eye.x, cam.eye.y, cam.eye.z);
            gl.uniform_3_f32(u.view_dir.as_ref(), view_dir.x, view_dir.y, view_dir.z);
            gl.uniform_1_i32(u.ortho.as_ref(), cam.ortho as i32);
            gl.uniform_1_i32(u.headlight.as_ref(), headlight as i32);
            gl.uniform_3_f32(u.light_dir.as_ref(), light_dir.x, light_dir.y, light_dir.z);
            gl.uniform_1_f32(u.ambient.as_ref(), style.ambient.clamp(0.0, 1.0));
            gl.uniform_1_i32(u.vertex_color.as_ref(), colored as i32);
            let [r, g, b] = style.color;
            gl.uniform_3_f32(u.color.as_ref(), r, g, b);

            gl.bind_vertex_array(Some(self.mesh_vao));
            if colored {
                gl.enable_vertex_attrib_array(2);
            } else {
                gl.disable_vertex_attrib_array(2);
            }
            gl.enable(glow::POLYGON_OFFSET_FILL);
            gl.disable(glow::BLEND);
            gl.depth_func(glow::LESS);
            gl.draw_elements(glow::TRIANGLES, (faces * 3) as i32, glow::UNSIGNED_INT, 0);
            gl.disable(glow::POLYGON_OFFSET_FILL);
            gl.bind_vertex_array(None);
        }
        check(gl, &format!("draw_mesh ({n} vertices, {faces} faces)"))
    }
}
