//! Helpers the visibility test files share (`tests/visibility*.rs`, each
//! with `mod visibility_support;`): the fitted cameras, the length shares
//! of agreement and of hidden line, and the depth-buffer method measured
//! against a reference, at the views' size, from
//! `shapecue::report::line_agreement` (the measures of `shapecue report
//! visibility` too).

#![allow(dead_code)]

use glam::Vec3;
use shapecue::mesh::Mesh;
use shapecue::render::Camera;
use shapecue::report::line_agreement;
use shapecue::spec::feature_lines::Segment;
use shapecue::spec::visibility::Pieces;

use crate::common;

pub use shapecue::report::line_agreement::{hidden_share, share};

/// The picture size of the views (and of the depth buffer).
pub const W: u32 = 480;
pub const H: u32 = 360;

pub fn f32s(m: &Mesh) -> Vec<[f32; 3]> {
    common::to_f32(&m.positions)
}

/// A camera fitted to the mesh from `dir`, orthographic when `ortho`.
pub fn camera(m: &Mesh, dir: Vec3, ortho: bool) -> Camera {
    line_agreement::fitted_camera(m, dir, ortho, W as f32 / H as f32).unwrap()
}

/// The depth-buffer method's agreement with `reference` (length share,
/// 32 points per segment), or `None` without headless GL.
pub fn depth_share(m: &Mesh, segs: &[Segment], cam: &Camera, reference: &[Pieces]) -> Option<f64> {
    let mut r = common::unless_no_gl(line_agreement::depth_renderer(W, H))?.unwrap();
    Some(line_agreement::depth_share(&mut r, m, segs, cam, reference).unwrap())
}
