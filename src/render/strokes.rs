//! Drawing curvature-directed strokes ([`crate::spec::sdf_lines`]): each
//! stroke's triangle strip (two vertices per traced point, tapered) is
//! projected with the frame's camera and drawn as flat-coloured clip-space
//! triangles through [`Renderer::draw_clip_triangles`], over whatever was
//! drawn before (the shaded isosurface, or nothing: white background).
//!
//! The strips lie on the interpolated surface, which the marching-cubes
//! triangles cut as chords; each vertex is lifted along its point's outward
//! normal by `lift` (world units, e.g. half a voxel) so that the strokes win
//! the depth test against the mesh without floating visibly above it; the
//! lift goes to the side of the surface facing the eye (an open or
//! two-sided surface such as a gyroid shows both sides).

use super::{Camera, Renderer};
use crate::error::Result;
use crate::spec::sdf_lines::Stroke;
use glam::{Vec3, Vec4};

/// How strokes are drawn.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct StrokeStyle {
    /// RGBA colour (alpha < 1 blends).
    pub color: [f32; 4],
    /// Multiplies every strip's width about its centre line.
    pub width_scale: f32,
    /// Lift along the outward normal, world units.
    pub lift: f32,
}

impl Default for StrokeStyle {
    fn default() -> Self {
        StrokeStyle {
            color: [0.05, 0.05, 0.1, 1.0],
            width_scale: 1.0,
            lift: 0.0,
        }
    }
}

/// The strokes' strips as world-space triangles (3 vertices each), widths
/// scaled and lifted towards `eye` as `style` says.
pub fn strip_triangles(strokes: &[Stroke], style: &StrokeStyle, eye: Vec3) -> Vec<Vec3> {
    let mut out = Vec::new();
    for s in strokes {
        let v: Vec<Vec3> = s
            .strip
            .chunks_exact(2)
            .zip(&s.normals)
            .flat_map(|(pair, n)| {
                let a = Vec3::from_array(pair[0].map(|c| c as f32));
                let b = Vec3::from_array(pair[1].map(|c| c as f32));
                let m = 0.5 * (a + b);
                let n = Vec3::from_array(n.map(|c| c as f32));
                let facing = if n.dot(eye - m) < 0.0 { -1.0 } else { 1.0 };
                let lift = n * (style.lift * facing);
                let h = 0.5 * (b - a) * style.width_scale;
                [m - h + lift, m + h + lift]
            })
            .collect();
        for i in 0..v.len().saturating_sub(2) {
            out.extend_from_slice(&[v[i], v[i + 1], v[i + 2]]);
        }
    }
    out
}

/// Draws `strokes` into the current frame of `renderer` (between
/// [`Renderer::begin`] with `camera` and [`Renderer::finish`]).
///
/// # Errors
///
/// Called outside a frame, or a GL failure.
pub fn draw(
    renderer: &mut Renderer,
    camera: &Camera,
    strokes: &[Stroke],
    style: &StrokeStyle,
) -> Result<()> {
    let vp = camera.view_proj(renderer.aspect());
    let clip: Vec<[f32; 4]> = strip_triangles(strokes, style, camera.eye)
        .into_iter()
        .map(|p| (vp * Vec4::from((p, 1.0))).to_array())
        .collect();
    renderer.draw_clip_triangles(&clip, style.color)
}
