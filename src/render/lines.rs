//! World-space line segments expanded to screen-aligned quads of a fixed pixel
//! width, in the same 4-vertex clip-space layout as House & Li's edge-out buffer
//! (so they go through [`Renderer::draw_clip_quads`](super::Renderer::draw_clip_quads)).
//!
//! Pure CPU code: the renderer calls it, and it is tested without a GL context.

use glam::{Mat4, Vec2, Vec4};

/// A world-space segment in clip space, cut at the near plane (OpenGL: inside
/// where z ≥ −w), with which ends were cut. `None` for a segment entirely
/// behind the near plane, with a non-finite point, or (only with a degenerate
/// projection) an end at w ≤ 0.
pub fn clip_segment(view_proj: Mat4, p: [f32; 3], q: [f32; 3]) -> Option<(Vec4, Vec4, [bool; 2])> {
    let a = view_proj * Vec4::from((glam::Vec3::from(p), 1.0));
    let b = view_proj * Vec4::from((glam::Vec3::from(q), 1.0));
    if !(a.is_finite() && b.is_finite()) {
        return None;
    }
    let (da, db) = (a.z + a.w, b.z + b.w);
    if da < 0.0 && db < 0.0 {
        return None;
    }
    let cut = [da < 0.0, db < 0.0];
    let (a, b) = match cut {
        [true, _] => (a + (b - a) * (da / (da - db)), b),
        [_, true] => (a, a + (b - a) * (da / (da - db))),
        _ => (a, b),
    };
    (a.w > 0.0 && b.w > 0.0).then_some((a, b, cut))
}

/// Expands segments (consecutive pairs of world-space points; a trailing odd
/// point is ignored) into clip-space quads, 4 vertices each, in the edge-out
/// order `s0 − p, s1 − p, s1 + p, s0 + p` where `p` is the screen-space
/// perpendicular (see [`Renderer::draw_clip_quads`](super::Renderer::draw_clip_quads)).
///
/// The quad is `width_px` pixels wide and extends `width_px / 2` past each end
/// (square caps), so consecutive segments of a polyline overlap instead of
/// leaving notches at their joints. A segment crossing the near plane is cut
/// at it; one entirely behind it, or with a non-finite point, produces nothing.
/// A segment that projects to a point becomes a `width_px` square.
pub fn segments_to_clip_quads(
    view_proj: Mat4,
    viewport: [u32; 2],
    segments: &[[f32; 3]],
    width_px: f32,
) -> Vec<[f32; 4]> {
    let half_size = Vec2::new(viewport[0] as f32, viewport[1] as f32) * 0.5;
    let hw = 0.5 * width_px.max(0.0);
    let mut out = Vec::with_capacity(segments.len() * 2);
    for seg in segments.chunks_exact(2) {
        let Some((a, b, _)) = clip_segment(view_proj, seg[0], seg[1]) else {
            continue;
        };
        // Pixel coordinates relative to the viewport centre.
        let sa = a.truncate().truncate() / a.w * half_size;
        let sb = b.truncate().truncate() / b.w * half_size;
        let d = (sb - sa).try_normalize().unwrap_or(Vec2::X) * hw;
        let p = d.perp();
        let to_clip = |s: Vec2, c: Vec4| {
            let ndc = s / half_size * c.w;
            [ndc.x, ndc.y, c.z, c.w]
        };
        out.push(to_clip(sa - d - p, a));
        out.push(to_clip(sb + d - p, b));
        out.push(to_clip(sb + d + p, b));
        out.push(to_clip(sa - d + p, a));
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_horizontal_segment_becomes_a_quad_of_the_requested_pixel_width() {
        // Identity projection: clip = world, viewport 100x50 → 50 and 25 pixels per unit.
        let q = segments_to_clip_quads(
            Mat4::IDENTITY,
            [100, 50],
            &[[-0.5, 0.0, 0.0], [0.5, 0.0, 0.0]],
            4.0,
        );
        assert_eq!(q.len(), 4);
        let px = |v: [f32; 4]| (v[0] / v[3] * 50.0, v[1] / v[3] * 25.0);
        // s0 − p, s1 − p, s1 + p, s0 + p with p = perp(s1 − s0) = +y, caps 2 px long.
        let expect = [(-27.0, -2.0), (27.0, -2.0), (27.0, 2.0), (-27.0, 2.0)];
        for (v, e) in q.iter().zip(expect) {
            let (x, y) = px(*v);
            assert!(
                (x - e.0).abs() < 1e-4 && (y - e.1).abs() < 1e-4,
                "{v:?} vs {e:?}"
            );
        }
    }

    #[test]
    fn segments_behind_the_near_plane_are_dropped_and_crossing_ones_cut() {
        let vp = glam::camera::rh::proj::opengl::perspective(1.0, 1.0, 0.1, 10.0);
        let behind = [[0.0, 0.0, 1.0], [0.1, 0.0, 2.0]];
        assert!(segments_to_clip_quads(vp, [64, 64], &behind, 2.0).is_empty());
        let crossing = [[0.0, 0.0, 1.0], [0.0, 0.1, -2.0]];
        let q = segments_to_clip_quads(vp, [64, 64], &crossing, 2.0);
        assert_eq!(q.len(), 4);
        assert!(
            q.iter()
                .all(|v| v.iter().all(|c| c.is_finite()) && v[3] > 0.0)
        );
        let nan = [[f32::NAN, 0.0, -1.0], [0.0, 0.0, -2.0]];
        assert!(segments_to_clip_quads(vp, [64, 64], &nan, 2.0).is_empty());
    }
}
