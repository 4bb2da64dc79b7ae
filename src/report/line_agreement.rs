//! How far two visibility methods of line segments agree, by line length:
//! the measures of `shapecue report visibility` and of the visibility tests
//! (`tests/visibility*.rs`), one implementation for both. The exact method
//! ([`crate::stages::visibility`]) and its f64 reference
//! ([`crate::cpu::visibility::classify_reference`]) give pieces along each
//! segment; the depth-buffer method ([`crate::render::depth_visibility`]) gives
//! visible polylines in pixels, read back here at 32 points per segment.
//!
//! The reference tests every face of the mesh per query, so on large meshes
//! it runs on a deterministic subset of a view's segments
//! ([`reference_subset`]): a segment's pieces depend only on its own plan,
//! so the subset's reference pieces are those of a reference over every
//! segment.

use crate::error::Result;
use crate::mesh::{Mesh, topology::vertex_normals};
use crate::render::depth_visibility::{DEFAULT_BIAS, segment_lines, visible_joined};
use crate::render::{Camera, Frame, MeshStyle, RenderOptions, Renderer};
use crate::spec::feature_lines::Segment;
use crate::spec::visibility::Pieces;
use crate::spec::visibility_plan::RayPlan;
use crate::spec::visibility_plan::agreement;
use glam::{Vec3, Vec4};

/// Points per segment at which the depth-buffer method is read.
pub const DEPTH_POINTS: usize = 32;

/// World length of a segment.
pub fn seg_len(s: &Segment) -> f64 {
    (0..3)
        .map(|k| f64::from(s.b[k] - s.a[k]).powi(2))
        .sum::<f64>()
        .sqrt()
}

/// Share of the length of `segs` on which the pieces `a` and `b` agree
/// (1 where the segments have no length).
pub fn share(segs: &[Segment], a: &[Pieces], b: &[Pieces]) -> f64 {
    let (mut same, mut total) = (0.0, 0.0);
    for ((s, a), b) in segs.iter().zip(a).zip(b) {
        let (x, y) = agreement(a, b, seg_len(s));
        same += x;
        total += y;
    }
    if total > 0.0 { same / total } else { 1.0 }
}

/// Hidden share of the length of `segs` by their `pieces`.
pub fn hidden_share(segs: &[Segment], pieces: &[Pieces]) -> f64 {
    let hidden: f64 = segs
        .iter()
        .zip(pieces)
        .map(|(g, p)| {
            let h: f64 = p
                .iter()
                .filter(|q| !q.2)
                .map(|q| f64::from(q.1 - q.0))
                .sum();
            h * seg_len(g)
        })
        .sum();
    hidden / segs.iter().map(seg_len).sum::<f64>().max(1e-30)
}

/// Whether `pieces` show the point at `t`.
pub fn shown(pieces: &Pieces, t: f32) -> bool {
    pieces.iter().find(|p| t <= p.1).is_some_and(|p| p.2)
}

/// `v` rounded to f32 (the positions the device, the twin and the renderer
/// read).
pub fn f32_positions(v: &[[f64; 3]]) -> Vec<[f32; 3]> {
    v.iter().map(|q| q.map(|c| c as f32)).collect()
}

/// A camera fitted to the mesh (its f32 positions' box) from direction
/// `dir`, for an image of `aspect` (width / height); orthographic, with
/// 1.1 × the box's diagonal in view, when `ortho`.
///
/// # Errors
/// A mesh without finite positions, a zero direction or a bad aspect.
pub fn fitted_camera(m: &Mesh, dir: Vec3, ortho: bool, aspect: f32) -> Result<Camera> {
    let p = f32_positions(&m.positions);
    let lo = p.iter().fold(Vec3::INFINITY, |a, q| a.min(Vec3::from(*q)));
    let hi = p
        .iter()
        .fold(Vec3::NEG_INFINITY, |a, q| a.max(Vec3::from(*q)));
    let cam = Camera::fit(lo, hi, dir, aspect)?;
    Ok(Camera {
        ortho_height: ortho.then(|| 1.1 * (hi - lo).length()),
        ..cam
    })
}

/// Sorts the segments of one extraction (its work-items append them in the
/// order they finish) by family and ends: the same list every run, so that
/// a subset of it is too.
pub fn sort_segments(segs: &mut [Segment]) {
    segs.sort_by_key(|s| {
        (
            s.family,
            s.a.map(f32::to_bits),
            s.b.map(f32::to_bits),
            s.ends,
        )
    });
}

/// The segments of `plan` the reference checks: every k-th (k ≥ 1), k the
/// least that keeps its ray–face tests (a query per sample and bisection
/// step, bounded by `intervals + 1` per segment, times `n_faces`) within
/// `budget`.
pub fn reference_subset(plan: &RayPlan, n_faces: usize, budget: f64) -> Vec<usize> {
    let casts: usize = plan.segs.iter().map(|s| s.intervals + 1).sum();
    let work = casts as f64 * n_faces as f64;
    let k = (work / budget.max(1.0)).ceil().max(1.0) as usize;
    (0..plan.segs.len()).step_by(k).collect()
}

/// The items of `all` at the indices `at`.
pub fn pick<T: Clone>(all: &[T], at: &[usize]) -> Vec<T> {
    at.iter().map(|&i| all[i].clone()).collect()
}

/// A renderer for the depth-buffer method: `width × height`, no
/// multisampling.
///
/// # Errors
/// [`crate::Error::NoGl`] where the machine has no headless OpenGL.
pub fn depth_renderer(width: u32, height: u32) -> Result<Renderer> {
    Renderer::new(RenderOptions {
        width,
        height,
        msaa: 0,
        background: [1.0; 4],
    })
}

/// The mesh (`positions` rounded to f32, `faces`) drawn from `cam`: its
/// depth is what the method tests against; `normals` as [`vertex_normals`]
/// gives them.
///
/// # Errors
/// OpenGL failures, a camera the renderer refuses.
pub fn depth_frame(
    r: &mut Renderer,
    positions: &[[f32; 3]],
    faces: &[[u32; 3]],
    normals: &[[f32; 3]],
    cam: &Camera,
) -> Result<Frame> {
    r.begin(cam)?;
    r.draw_mesh(positions, normals, &[], faces, MeshStyle::default())?;
    r.finish()
}

/// The depth-buffer method's agreement with `reference` (the pieces of
/// `segs`) as a length share, read at [`DEPTH_POINTS`] points per segment,
/// each segment tested alone against the depth of the mesh drawn by `r`
/// from `cam`.
///
/// # Errors
/// OpenGL failures, a camera the renderer refuses.
pub fn depth_share(
    r: &mut Renderer,
    m: &Mesh,
    segs: &[Segment],
    cam: &Camera,
    reference: &[Pieces],
) -> Result<f64> {
    let p = f32_positions(&m.positions);
    let frame = depth_frame(r, &p, &m.faces, &vertex_normals(m), cam)?;
    Ok(depth_share_in(&frame, cam, segs, reference))
}

/// [`depth_share`] against a frame already drawn from `cam`.
pub fn depth_share_in(frame: &Frame, cam: &Camera, segs: &[Segment], reference: &[Pieces]) -> f64 {
    let (w, h) = (frame.width as f32, frame.height as f32);
    let vp = cam.view_proj(w / h);
    let px = |q: [f32; 3]| {
        let c = vp * Vec4::new(q[0], q[1], q[2], 1.0);
        let [x, y, _] = crate::spec::view::clip_to_pixel(c.to_array(), frame.width, frame.height);
        [x, y]
    };
    let (mut same, mut total) = (0.0, 0.0);
    for (s, refp) in segs.iter().zip(reference) {
        let lines = segment_lines(vp, std::slice::from_ref(s), s.family, |_| 1.0);
        let vis = visible_joined(&lines, frame, DEFAULT_BIAS);
        let (a, b) = (px(s.a), px(s.b));
        let d = [b[0] - a[0], b[1] - a[1]];
        let dd = (d[0] * d[0] + d[1] * d[1]).max(1e-12);
        let param = |q: [f32; 2]| ((q[0] - a[0]) * d[0] + (q[1] - a[1]) * d[1]) / dd;
        let len = seg_len(s) / DEPTH_POINTS as f64;
        for k in 0..DEPTH_POINTS {
            let t = (k as f32 + 0.5) / DEPTH_POINTS as f32;
            let q = px(std::array::from_fn(|i| s.a[i] + t * (s.b[i] - s.a[i])));
            let u = param(q);
            let on = vis.iter().any(|l| {
                let first = l.points[0];
                let last = l.points.last().copied().unwrap_or(first);
                let (u0, u1) = (param(first), param(last));
                u >= u0.min(u1) - 1e-4 && u <= u0.max(u1) + 1e-4
            });
            total += len;
            if on == shown(refp, t) {
                same += len;
            }
        }
    }
    if total > 0.0 { same / total } else { 1.0 }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn seg(a: [f32; 3], b: [f32; 3]) -> Segment {
        Segment::new(a, b, 0, 1.0, [[0, 1], [1, 2]])
    }

    #[test]
    fn shares_weigh_by_length() {
        let segs = [
            seg([0.0; 3], [1.0, 0.0, 0.0]),
            seg([0.0; 3], [3.0, 0.0, 0.0]),
        ];
        let all: Pieces = vec![(0.0, 1.0, true)];
        let half: Pieces = vec![(0.0, 0.5, true), (0.5, 1.0, false)];
        let a = [all.clone(), all.clone()];
        let b = [all.clone(), half.clone()];
        // The second segment (3 of 4 units) differs on its second half.
        assert!((share(&segs, &a, &b) - 2.5 / 4.0).abs() < 1e-12);
        assert!((hidden_share(&segs, &b) - 1.5 / 4.0).abs() < 1e-12);
        assert_eq!(share(&[], &[], &[]), 1.0);
        assert!(shown(&half, 0.25) && !shown(&half, 0.75));
    }
}
