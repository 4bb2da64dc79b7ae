//! Shared types of the `intersections` family (see [`crate::spec`]): the
//! curves where faces of a mesh cross each other, Blender Line Art's
//! "intersection" lines. The output type ([`Segment`], one per crossing face
//! pair), the options ([`IntersectionOptions`]: optional per-face groups),
//! what a search reports beside its segments ([`IntersectionStats`]), the
//! sizes ([`intersections_bound`], [`intersections_estimate`]), the
//! canonical order ([`sort_canonical`]) and the entry points
//! ([`IsectKernel`]).
//!
//! Mirror in `kernels/intersections.cl`: `IsectSegment` (field by field; a
//! probe kernel test in `stages::intersections` compares sizes and offsets)
//! and `ISECT_STACK` (passed as a `-D` option by the host from
//! [`crate::spec::bvh::STACK_DEPTH`]). The tree it traverses is the `bvh`
//! family's (`kernels/common/bvh_tree.h`: `BvhNode`, `BvhBox`).
//!
//! Which pairs are tested: every pair of faces whose boxes overlap, once
//! (the lower face index asks), except faces that share a vertex (the same
//! vertex index, or only the same position, bit for bit, as in an unwelded
//! soup) and, when groups are given, faces of the same group. Which pairs
//! give a segment: those whose triangles cross along a line of positive
//! length; coplanar pairs, degenerate (zero-area) faces and pairs that only
//! touch at a point give none.

use crate::error::{Error, Result};
use bytemuck::{Pod, Zeroable};

/// One intersection segment (`IsectSegment` in the kernel): where faces
/// `faces[0] < faces[1]` cross, from `a` to `b`. The segment runs along
/// `n0 × n1` (the faces' normals `(v1 − v0) × (v2 − v0)`, in that order).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct Segment {
    /// First end.
    pub a: [f32; 3],
    /// Second end.
    pub b: [f32; 3],
    /// The two faces, lower index first.
    pub faces: [u32; 2],
}
const _: () = assert!(std::mem::size_of::<Segment>() == 32);

/// `(name, byte offset)` of every field of [`Segment`] and its size, as the
/// probe kernel reports them (`struct.field`, `struct.(size)`).
pub fn field_offsets() -> [(&'static str, usize); 4] {
    use std::mem::{offset_of, size_of};
    [
        ("IsectSegment.a", offset_of!(Segment, a)),
        ("IsectSegment.b", offset_of!(Segment, b)),
        ("IsectSegment.faces", offset_of!(Segment, faces)),
        ("IsectSegment.(size)", size_of::<Segment>()),
    ]
}

/// How a search chooses its pairs.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct IntersectionOptions {
    /// One group id per face: only faces of different groups are tested
    /// (two inputs of a scene crossed after their meshes are concatenated:
    /// group 0 for the first mesh's faces, 1 for the second's). `None`:
    /// every pair of faces that share no vertex is tested (self-intersection).
    pub groups: Option<Vec<u32>>,
}

impl IntersectionOptions {
    /// Every face in group `g` of its input: `counts[g]` faces each, in
    /// order (the face lists of the inputs concatenated).
    pub fn by_input(counts: &[usize]) -> IntersectionOptions {
        let groups = (counts.iter().enumerate())
            .flat_map(|(g, &n)| std::iter::repeat_n(g as u32, n))
            .collect();
        IntersectionOptions {
            groups: Some(groups),
        }
    }

    /// Checks the options against a mesh of `n_faces` faces (`what` names
    /// the mesh in errors).
    pub fn check(&self, what: &str, n_faces: usize) -> Result<()> {
        match &self.groups {
            Some(g) if g.len() != n_faces => Err(Error::InvalidArgument(format!(
                "{what}: {} group ids for {n_faces} faces (one per face expected)",
                g.len()
            ))),
            _ => Ok(()),
        }
    }
}

/// What a search did besides its segments (device and twin report the
/// same numbers).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct IntersectionStats {
    /// Face pairs given the triangle test: boxes overlap, no shared vertex,
    /// different groups (saturates at `u32::MAX`).
    pub pairs_tested: u32,
    /// Segments found.
    pub segments: usize,
    /// Whether the output buffer was too small and the search ran again
    /// with room for every segment (device only).
    pub reran: bool,
}

/// Most segments a mesh of `n_faces` faces can give: one per pair of faces,
/// `n (n − 1) / 2` (every face crossing every other). A true bound, far
/// above what real meshes give (see [`intersections_estimate`]).
pub fn intersections_bound(n_faces: usize) -> u64 {
    let n = n_faces as u64;
    n * n.saturating_sub(1) / 2
}

/// The room the device's output starts with for `n_faces` faces: one
/// segment per 16 faces plus 256. Crossing surfaces give segments along
/// curves (about √n of them for two crossing spheres); a search that finds
/// more counts them all, grows the buffer to the count and runs once more.
pub fn intersections_estimate(n_faces: usize) -> usize {
    n_faces / 16 + 256
}

/// Most segments one device search can count (its counter is a `u32`).
pub const MAX_SEGMENTS: usize = u32::MAX as usize - 1;

/// The canonical order of a search's segments: by face pair. Each pair
/// gives at most one segment, so the order is total, and device and twin
/// outputs sorted so compare element by element.
pub fn sort_canonical(segments: &mut [Segment]) {
    segments.sort_unstable_by_key(|s| (s.faces[0], s.faces[1]));
}

crate::spec::kernels::kernel_entries! {
    /// The entry points of `kernels/intersections.cl`.
    pub enum IsectKernel {
        /// One work-item per leaf: traverse the tree with the face's box,
        /// test the triangles of higher-numbered faces, append segments.
        Find = "isect_find",
        /// Layout probe (appended by the probe test only).
        ProbeLayout = "isect_probe_layout",
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn bounds_groups_and_order() {
        assert_eq!(intersections_bound(0), 0);
        assert_eq!(intersections_bound(1), 0);
        assert_eq!(intersections_bound(4), 6);
        assert!(intersections_bound(usize::MAX >> 1) > 0);
        assert_eq!(intersections_estimate(0), 256);
        let o = IntersectionOptions::by_input(&[2, 0, 3]);
        assert_eq!(o.groups.as_deref(), Some(&[0, 0, 2, 2, 2][..]));
        assert!(o.check("m", 5).is_ok());
        let e = o.check("m", 4).unwrap_err().to_string();
        assert!(e.contains("5 group ids for 4 faces"), "{e}");
        assert!(IntersectionOptions::default().check("m", 9).is_ok());
        let seg = |f0, f1| Segment {
            faces: [f0, f1],
            ..Segment::default()
        };
        let mut s = vec![seg(3, 4), seg(1, 9), seg(1, 2)];
        sort_canonical(&mut s);
        let pairs: Vec<[u32; 2]> = s.iter().map(|s| s.faces).collect();
        assert_eq!(pairs, [[1, 2], [1, 9], [3, 4]]);
    }
}
