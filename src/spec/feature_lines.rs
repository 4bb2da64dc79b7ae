//! Shared types of the `feature_lines` family (occluding and suggestive
//! contours, DeCarlo et al. 2003): what the stage reads of a view, the
//! segment type and the bound of the segment buffer. Used by the host wiring
//! (`stages::feature_lines`) and the CPU twin
//! (`cpu::feature_lines`).

/// A segment: endpoints, kind (0 contour, 1 suggestive), strength, and the
/// mesh edge each endpoint lies on (sorted vertex pairs). The segments of two
/// faces sharing an edge meet on it, so chaining by these edges is exact
/// (see [`edge_key`]).
pub type Segment = ([f32; 3], [f32; 3], u32, f32, [[u32; 2]; 2]);

/// One number per mesh edge (a sorted vertex pair), for chaining segments.
pub fn edge_key(e: [u32; 2]) -> u64 {
    (u64::from(e[0]) << 32) | u64::from(e[1])
}

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

/// Segments the face pass can emit for `faces` faces: one of each kind per
/// face (a plane crosses a triangle in at most one segment), the capacity of
/// the device's segment buffer.
pub fn segments_bound(faces: usize) -> usize {
    2 * faces
}

crate::spec::kernels::kernel_entries! {
    /// The entry points of `kernels/feature_lines.cl`.
    pub enum LinesKernel {
        /// Per-vertex n·v and radial curvature.
        Vertex = "lines_vertex",
        /// One contour or suggestive-contour segment per face.
        Face = "lines_face",
    }
}
