//! Shared types of the `feature_lines` family (occluding and suggestive
//! contours, DeCarlo et al. 2003): what the stage reads of a view, the
//! segment type and the bound of the segment buffer. Used by the host wiring
//! (`stages::feature_lines`) and the CPU twin
//! (`cpu::feature_lines`).

use crate::spec::view::View;

/// A segment: endpoints, kind (0 contour, 1 suggestive) and strength.
pub type Segment = ([f32; 3], [f32; 3], u32, f32);

/// Inputs of the stage, f32 per vertex.
pub struct LineInputs<'a> {
    /// Positions.
    pub pos: &'a [[f32; 3]],
    /// Unit normals.
    pub nrm: &'a [[f32; 3]],
    /// First principal directions.
    pub d1: &'a [[f32; 3]],
    /// Second principal directions.
    pub d2: &'a [[f32; 3]],
    /// (k1, k2).
    pub k: &'a [[f32; 2]],
    /// (C111, C112, C122, C222).
    pub dk: &'a [[f32; 4]],
}

/// What line extraction reads of a view: the eye (perspective) or the
/// constant direction towards the viewer (orthographic). Implemented by the
/// one view type, [`View`] (`-dir`, i.e. `eye − target`, when orthographic),
/// and by [`EyeView`], the eye-only form older callers build.
pub trait LineView: Copy {
    /// The eye, or the direction towards the viewer when [`is_ortho`](Self::is_ortho).
    fn line_eye(&self) -> [f32; 3];
    /// Orthographic projection.
    fn is_ortho(&self) -> bool;
}

impl LineView for View {
    fn line_eye(&self) -> [f32; 3] {
        if self.ortho {
            self.toward_viewer().to_array()
        } else {
            self.eye.to_array()
        }
    }
    fn is_ortho(&self) -> bool {
        self.ortho
    }
}

/// The eye-only view that line extraction took before [`View`] existed
/// (still built by tests and the pose pipeline; new code passes a [`View`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct EyeView {
    /// Eye position, or direction towards the viewer when `ortho`.
    pub eye: [f32; 3],
    /// Orthographic projection.
    pub ortho: bool,
}

impl LineView for EyeView {
    fn line_eye(&self) -> [f32; 3] {
        self.eye
    }
    fn is_ortho(&self) -> bool {
        self.ortho
    }
}

/// Segments the face pass can emit for `faces` faces: one of each kind per
/// face (a plane crosses a triangle in at most one segment), the capacity of
/// the device's segment buffer.
pub fn segments_bound(faces: usize) -> usize {
    2 * faces
}
