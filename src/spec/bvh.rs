//! Shared types of the `bvh` family (see [`crate::spec`]): a linear BVH over
//! a mesh's faces (Karras 2012), its node layout ([`BvhNode`], [`BvhBox`],
//! [`LEAF`], [`NONE`]), the Morton codes of the face centroids ([`morton3`],
//! [`MortonFrame`]), the sizes ([`bvh_bound`]), the occlusion query
//! ([`BvhQuery`], its epsilons and [`STACK_DEPTH`]) and the entry points
//! ([`BvhKernel`]).
//!
//! Mirrors in `kernels/bvh.cl`: `BvhNode`, `BvhBox`, `BvhQuery` (field by
//! field; a probe kernel test in `stages::bvh` compares sizes and offsets),
//! `BVH_LEAF`, `BVH_NONE`, `BVH_STACK`, `BVH_EDGE_EPS`, `BVH_END_EPS`,
//! `BVH_BOX_PAD` (passed as `-D` options by the host from these constants).
//!
//! Numbering: `n` faces give `n` leaves (leaf `i` is the `i`-th face in
//! Morton order, `faces_sorted[i]`) and `n − 1` internal nodes, node 0 the
//! root (for `n = 1` the root is leaf 0; for `n = 0` there is no tree). A
//! child reference is an internal node index, or [`LEAF`]` | leaf`.

use bytemuck::{Pod, Zeroable};

/// Bit set in a child reference that names a leaf.
pub const LEAF: u32 = 1 << 31;
/// No node: the root's parent, an unused exclusion slot.
pub const NONE: u32 = u32::MAX;
/// Bits of a Morton code (10 per axis).
pub const MORTON_BITS: u32 = 30;
/// Most faces a tree holds (leaf indices must stay below [`LEAF`]).
pub const MAX_FACES: usize = (LEAF - 1) as usize;

/// Entries of the traversal stack of `bvh_occluded`. The tree's depth is at
/// most 63 (each internal node splits its range at a strictly longer common
/// prefix of the 62-bit augmented key (morton, index)), and the traversal
/// keeps at most one pending child per level, so 64 never overflows; the
/// kernel still checks and counts overflow instead of writing past the end.
pub const STACK_DEPTH: usize = 64;

/// Barycentric slack of the segment–triangle test, relative to the scaled
/// determinant: a triangle counts as hit when u, v ≥ −ε and u + v ≤ 1 + ε.
/// Triangles grow by ε of their size, so a segment through an edge shared
/// by two faces hits at least one of them (no leak through cracks): the
/// conservative side for occlusion.
pub const EDGE_EPS: f32 = 1e-5;
/// Ends trimmed off the segment: a hit counts only for
/// t ∈ (ε, 1 − ε) (t the fraction of the segment from origin to target), so
/// a point on the surface is not occluded by the faces it lies on.
pub const END_EPS: f32 = 1e-4;
/// Padding of every box in the traversal's slab test, relative to the box's
/// largest extent (plus a tiny absolute term): covers the triangles' growth
/// by [`EDGE_EPS`] and the rounding of the slab divisions, so no box that
/// holds a hit is culled.
pub const BOX_PAD: f32 = 1e-4;

/// An internal node (`BvhNode` in the kernel): two child references and the
/// parent (internal index, [`NONE`] for the root).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Pod, Zeroable)]
pub struct BvhNode {
    /// Left child: internal index or `LEAF | leaf`.
    pub left: u32,
    /// Right child.
    pub right: u32,
    /// Parent internal node, or [`NONE`].
    pub parent: u32,
    /// Zero.
    pub pad: u32,
}
const _: () = assert!(std::mem::size_of::<BvhNode>() == 16);

/// An axis-aligned box (`BvhBox` in the kernel: `float4 lo, hi`, `w` = 0).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct BvhBox {
    /// Minimum corner (x, y, z, 0).
    pub lo: [f32; 4],
    /// Maximum corner (x, y, z, 0).
    pub hi: [f32; 4],
}
const _: () = assert!(std::mem::size_of::<BvhBox>() == 32);

/// One occlusion query (`BvhQuery` in the kernel): is the open segment from
/// `origin` to `target` crossed by a face other than the excluded ones?
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct BvhQuery {
    /// Segment start (x, y, z, 0).
    pub origin: [f32; 4],
    /// Segment end (x, y, z, 0).
    pub target: [f32; 4],
    /// Face indices (mesh numbering) not tested; unused slots [`NONE`].
    pub exclude: [u32; 4],
}
const _: () = assert!(std::mem::size_of::<BvhQuery>() == 48);

/// Result of a query (`u32` per query).
pub const VISIBLE: u32 = 0;
/// The segment is blocked.
pub const OCCLUDED: u32 = 1;
/// The traversal stack overflowed (counted in the counters buffer): unknown.
pub const OVERFLOW: u32 = 2;

impl BvhQuery {
    /// A query with up to four excluded faces (more are an error of the caller:
    /// only the first four are kept).
    pub fn new(origin: [f32; 3], target: [f32; 3], exclude: &[u32]) -> BvhQuery {
        let mut ex = [NONE; 4];
        for (slot, &f) in ex.iter_mut().zip(exclude) {
            *slot = f;
        }
        BvhQuery {
            origin: [origin[0], origin[1], origin[2], 0.0],
            target: [target[0], target[1], target[2], 0.0],
            exclude: ex,
        }
    }
}

/// `(name, byte offset)` of every field of the three structs and their
/// sizes, as the probe kernel reports them (`struct.field`, `struct.(size)`).
pub fn field_offsets() -> [(&'static str, usize); 12] {
    use std::mem::{offset_of, size_of};
    [
        ("BvhNode.left", offset_of!(BvhNode, left)),
        ("BvhNode.right", offset_of!(BvhNode, right)),
        ("BvhNode.parent", offset_of!(BvhNode, parent)),
        ("BvhNode.pad", offset_of!(BvhNode, pad)),
        ("BvhNode.(size)", size_of::<BvhNode>()),
        ("BvhBox.lo", offset_of!(BvhBox, lo)),
        ("BvhBox.hi", offset_of!(BvhBox, hi)),
        ("BvhBox.(size)", size_of::<BvhBox>()),
        ("BvhQuery.origin", offset_of!(BvhQuery, origin)),
        ("BvhQuery.target", offset_of!(BvhQuery, target)),
        ("BvhQuery.exclude", offset_of!(BvhQuery, exclude)),
        ("BvhQuery.(size)", size_of::<BvhQuery>()),
    ]
}

/// Sizes of a tree over `n_faces` faces: `(leaves, internal nodes)` =
/// `(n, n − 1)` (`(0, 0)` for no face). Buffers: `keys`, `faces_sorted`,
/// `leaf_parent`, `leaf_boxes` hold `leaves`; `nodes`, `node_boxes`,
/// `visits` hold `internal`, `child_boxes` twice that (each at least one
/// element on the device).
pub fn bvh_bound(n_faces: usize) -> (usize, usize) {
    (n_faces, n_faces.saturating_sub(1))
}

/// The 10 low bits of `v` spread to every third bit (bit k to bit 3k).
pub const fn expand_bits(v: u32) -> u32 {
    let mut v = v & 0x3ff;
    v = v.wrapping_mul(0x0001_0001) & 0xff00_00ff;
    v = v.wrapping_mul(0x0000_0101) & 0x0f00_f00f;
    v = v.wrapping_mul(0x0000_0011) & 0xc30c_30c3;
    v = v.wrapping_mul(0x0000_0005) & 0x4924_9249;
    v
}

/// The 30-bit Morton code of cell `(x, y, z)` (each below 1024): x in the
/// highest bit of each triple (`x·4 + y·2 + z`, as Karras).
pub const fn morton3(x: u32, y: u32, z: u32) -> u32 {
    expand_bits(x) * 4 + expand_bits(y) * 2 + expand_bits(z)
}

/// How face centroids map onto the 1024³ grid: a centroid's coordinate sum
/// `s = (a + b) + c` (f32, per axis) goes to cell
/// `clamp(floor((s − lo3) · scale), 0, 1023)` (NaN to 0). `lo3 = 3 · lo` and
/// `scale = 1024 / (3 · extent)` over the box of the positions; an axis of
/// zero (or not representable) extent has `scale = 0`, every cell 0.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct MortonFrame {
    /// Three times the low corner of the positions' box.
    pub lo3: [f32; 3],
    /// Cells per unit of coordinate sum.
    pub scale: [f32; 3],
}

impl MortonFrame {
    /// The frame of `positions` (assumed finite; an empty slice gives the
    /// zero frame).
    pub fn of(positions: &[[f32; 3]]) -> MortonFrame {
        let mut f = MortonFrame::default();
        if positions.is_empty() {
            return f;
        }
        for k in 0..3 {
            let lo = positions.iter().map(|p| p[k]).fold(f32::INFINITY, f32::min);
            let hi = positions
                .iter()
                .map(|p| p[k])
                .fold(f32::NEG_INFINITY, f32::max);
            f.lo3[k] = 3.0 * lo;
            let extent = 3.0 * hi - 3.0 * lo;
            let scale = 1024.0 / extent;
            f.scale[k] = if extent > 0.0 && scale.is_finite() {
                scale
            } else {
                0.0
            };
        }
        f
    }

    /// The cell of a coordinate sum `s` on axis `k` (the kernel's `bvh_cell`).
    pub fn cell(&self, k: usize, s: f32) -> u32 {
        let v = (s - self.lo3[k]) * self.scale[k];
        if v.is_nan() || v <= 0.0 {
            0
        } else if v >= 1023.0 {
            1023
        } else {
            v as u32
        }
    }

    /// The Morton code of the triangle `(a, b, c)`.
    pub fn code(&self, a: [f32; 3], b: [f32; 3], c: [f32; 3]) -> u32 {
        let cell = |k: usize| self.cell(k, a[k] + b[k] + c[k]);
        morton3(cell(0), cell(1), cell(2))
    }
}

crate::spec::kernels::kernel_entries! {
    /// The entry points of `kernels/bvh.cl`.
    pub enum BvhKernel {
        /// Morton code of each face's centroid, (code, face) pairs.
        Morton = "bvh_morton",
        /// Karras's internal nodes from the sorted codes.
        Build = "bvh_build",
        /// Leaf boxes, then internal boxes bottom-up (visit counters).
        Refit = "bvh_refit",
        /// Segment occlusion queries by stack traversal.
        Occluded = "bvh_occluded",
        /// Layout probe (appended by the probe test only).
        ProbeLayout = "bvh_probe_layout",
    }
}

/// A built tree: sorted codes and faces (leaf order), internal nodes, leaf
/// parents and boxes, as the device's buffers hold them (the device stage
/// reads it back; the twin builds and walks it, `cpu::bvh`).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Tree {
    /// Morton codes in leaf order.
    pub keys: Vec<u32>,
    /// The face of each leaf.
    pub faces_sorted: Vec<u32>,
    /// Internal nodes (node 0 the root).
    pub nodes: Vec<BvhNode>,
    /// Parent of each leaf ([`NONE`] for a lone leaf).
    pub leaf_parent: Vec<u32>,
    /// Box of each internal node.
    pub node_boxes: Vec<BvhBox>,
    /// Box of each leaf.
    pub leaf_boxes: Vec<BvhBox>,
    /// The two children's boxes of each internal node, padded as the
    /// traversal tests them (`cpu::bvh::padded`): `2·node` the left, `2·node + 1`
    /// the right (one read of 64 bytes per node visited).
    pub child_boxes: Vec<BvhBox>,
}

/// The input checks of a BVH's mesh, which the device stage and the twin
/// both run before they build.
/// Checks that every face names existing vertices and that the tree can
/// number the faces; `what` names the mesh in errors.
pub fn check_faces(what: &str, n_vertices: usize, faces: &[[u32; 3]]) -> crate::error::Result<()> {
    if faces.len() > MAX_FACES {
        return Err(crate::error::Error::InvalidArgument(format!(
            "{what}: {} faces, a BVH holds at most {MAX_FACES}",
            faces.len()
        )));
    }
    for (i, f) in faces.iter().enumerate() {
        if let Some(&v) = f.iter().find(|&&v| v as usize >= n_vertices) {
            return Err(crate::error::Error::InvalidInput {
                source_name: what.to_string(),
                element: format!("face {i}"),
                problem: format!("vertex index {v} out of range ({n_vertices} vertices)"),
            });
        }
    }
    Ok(())
}

/// Checks that there are `n_vertices` finite positions.
pub fn check_positions(
    what: &str,
    n_vertices: usize,
    positions: &[[f32; 3]],
) -> crate::error::Result<()> {
    if positions.len() != n_vertices {
        return Err(crate::error::Error::InvalidArgument(format!(
            "{what}: {} positions for {n_vertices} vertices",
            positions.len()
        )));
    }
    match positions
        .iter()
        .position(|p| p.iter().any(|c| !c.is_finite()))
    {
        Some(i) => Err(crate::error::Error::InvalidInput {
            source_name: what.to_string(),
            element: format!("vertex {i}"),
            problem: "position is not finite".to_string(),
        }),
        None => Ok(()),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn morton_interleaves_ten_bits_per_axis() {
        assert_eq!(morton3(0, 0, 0), 0);
        assert_eq!(morton3(1, 0, 0), 4);
        assert_eq!(morton3(0, 1, 0), 2);
        assert_eq!(morton3(0, 0, 1), 1);
        assert_eq!(morton3(1023, 1023, 1023), (1 << 30) - 1);
        for v in [0u32, 1, 5, 511, 1023] {
            let e = expand_bits(v);
            for b in 0..10 {
                assert_eq!((e >> (3 * b)) & 1, (v >> b) & 1);
            }
            assert_eq!(e & !0x0924_9249, 0);
        }
    }

    #[test]
    fn frame_clamps_and_survives_flat_and_extreme_boxes() {
        let f = MortonFrame::of(&[[0.0, 1.0, 1e6], [1.0, 1.0, 1e6 + 1e-6]]);
        assert_eq!(f.scale[1], 0.0);
        assert_eq!(f.cell(0, 0.0), 0);
        assert_eq!(f.cell(0, 3.0), 1023);
        assert_eq!(f.cell(0, -5.0), 0);
        assert_eq!(f.cell(0, f32::NAN), 0);
        assert_eq!(f.cell(0, 1.5), 512);
        let tiny = MortonFrame::of(&[[0.0; 3], [1e-38, 0.0, 0.0]]);
        assert!(tiny.scale.iter().all(|s| s.is_finite()));
        assert_eq!(bvh_bound(0), (0, 0));
        assert_eq!(bvh_bound(1), (1, 0));
        assert_eq!(bvh_bound(5), (5, 4));
    }
}
