//! Helpers the visibility test files share (`tests/visibility*.rs`, each
//! with `mod visibility_support;`): the fitted cameras, the length shares
//! of agreement and of hidden line, and the depth-buffer method measured
//! against a reference.

#![allow(dead_code)]

use glam::{Vec3, Vec4};
use shapecue::cpu::visibility::agreement;
use shapecue::mesh::{Mesh, topology::vertex_normals};
use shapecue::render::visibility::{DEFAULT_BIAS, segment_lines, visible_joined};
use shapecue::render::{Camera, Frame, MeshStyle, RenderOptions, Renderer};
use shapecue::spec::feature_lines::Segment;
use shapecue::spec::visibility::Pieces;

use crate::common;

/// The picture size of the views (and of the depth buffer).
pub const W: u32 = 480;
pub const H: u32 = 360;

pub fn f32s(m: &Mesh) -> Vec<[f32; 3]> {
    common::to_f32(&m.positions)
}

/// A camera fitted to the mesh from `dir`, orthographic when `ortho`.
pub fn camera(m: &Mesh, dir: Vec3, ortho: bool) -> Camera {
    let p = f32s(m);
    let lo = p.iter().fold(Vec3::INFINITY, |a, q| a.min(Vec3::from(*q)));
    let hi = p
        .iter()
        .fold(Vec3::NEG_INFINITY, |a, q| a.max(Vec3::from(*q)));
    let cam = Camera::fit(lo, hi, dir, W as f32 / H as f32).unwrap();
    Camera {
        ortho_height: ortho.then(|| 1.1 * (hi - lo).length()),
        ..cam
    }
}

pub fn seg_len(s: &Segment) -> f64 {
    (0..3)
        .map(|k| f64::from(s.1[k] - s.0[k]).powi(2))
        .sum::<f64>()
        .sqrt()
}

/// Length share on which `a` and `b` agree.
pub fn share(segs: &[Segment], a: &[Pieces], b: &[Pieces]) -> f64 {
    let (mut same, mut total) = (0.0, 0.0);
    for ((s, a), b) in segs.iter().zip(a).zip(b) {
        let (x, y) = agreement(a, b, seg_len(s));
        same += x;
        total += y;
    }
    if total > 0.0 { same / total } else { 1.0 }
}

/// Hidden share of the length of `segs`.
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

/// The depth-buffer method's agreement with `reference` (length share,
/// 32 points per segment), or `None` without headless GL.
pub fn depth_share(m: &Mesh, segs: &[Segment], cam: &Camera, reference: &[Pieces]) -> Option<f64> {
    let o = RenderOptions {
        width: W,
        height: H,
        msaa: 0,
        background: [1.0; 4],
    };
    let mut r = common::unless_no_gl(Renderer::new(o))?.unwrap();
    let p = f32s(m);
    r.begin(cam).unwrap();
    r.draw_mesh(&p, &vertex_normals(m), &[], &m.faces, MeshStyle::default())
        .unwrap();
    let frame: Frame = r.finish().unwrap();
    let vp = cam.view_proj(W as f32 / H as f32);
    let px = |q: [f32; 3]| {
        let c = vp * Vec4::new(q[0], q[1], q[2], 1.0);
        [
            (c.x / c.w * 0.5 + 0.5) * W as f32,
            (0.5 - c.y / c.w * 0.5) * H as f32,
        ]
    };
    let (mut same, mut total) = (0.0, 0.0);
    for (s, refp) in segs.iter().zip(reference) {
        let lines = segment_lines(vp, std::slice::from_ref(s), s.2, |_| 1.0);
        let vis = visible_joined(&lines, &frame, DEFAULT_BIAS);
        let (a, b) = (px(s.0), px(s.1));
        let d = [b[0] - a[0], b[1] - a[1]];
        let dd = (d[0] * d[0] + d[1] * d[1]).max(1e-12);
        let param = |q: [f32; 2]| ((q[0] - a[0]) * d[0] + (q[1] - a[1]) * d[1]) / dd;
        let len = seg_len(s) / 32.0;
        for k in 0..32 {
            let t = (k as f32 + 0.5) / 32.0;
            let q = px(std::array::from_fn(|i| s.0[i] + t * (s.1[i] - s.0[i])));
            let u = param(q);
            let on = vis.iter().any(|l| {
                let (u0, u1) = (param(l.points[0]), param(*l.points.last().unwrap()));
                u >= u0.min(u1) - 1e-4 && u <= u0.max(u1) + 1e-4
            });
            total += len;
            if on == shown(refp, t) {
                same += len;
            }
        }
    }
    Some(if total > 0.0 { same / total } else { 1.0 })
}
