//! The kernel file of every family, with the shared headers it is
//! assembled from: the one place that says which file under `kernels/` a
//! family builds, so that `src/gpu` knows no family. A family's host module
//! builds its program from the constant named after it, and creates its
//! kernels from its entry-point enum in `spec` (`spec::kernels`).

use crate::gpu::{COMMON_HEADERS, KernelFile};

/// `(path under kernels/, text)` of a header or included file.
type Source = (&'static str, &'static str);

macro_rules! source {
    ($path:literal) => {
        ($path, include_str!(concat!("../../kernels/", $path)))
    };
}

const REAL_H: Source = COMMON_HEADERS[0];
const HASH_H: Source = source!("common/hash.h");
const MC_EDGE_H: Source = source!("common/mc_edge.h");
const MC_CELL_H: Source = source!("common/mc_cell.h");
const MC_DIRECT_H: Source = source!("common/mc_direct.h");
const BVH_TREE_H: Source = source!("common/bvh_tree.h");

/// `kernels/curvature.cl`: the shared passes, then (by `#include`) the face
/// arithmetic, the lane loads, and one accumulation scheme's file
/// (`curvature_atomic.cl`, or `curvature_gather.cl` under `SC_GATHER`).
pub const CURVATURE: KernelFile = KernelFile {
    name: "kernels/curvature.cl",
    source: include_str!("../../kernels/curvature.cl"),
    headers: COMMON_HEADERS,
    includes: &[
        source!("common/curvature_face.h"),
        source!("common/curvature_lanes.h"),
        source!("curvature_atomic.cl"),
        source!("curvature_gather.cl"),
    ],
};

/// `kernels/scan.cl`: exclusive scans.
pub const SCAN: KernelFile = plain("kernels/scan.cl", include_str!("../../kernels/scan.cl"));

/// `kernels/radix_sort.cl`: (key, value) pairs sorted by key.
pub const RADIX_SORT: KernelFile = plain(
    "kernels/radix_sort.cl",
    include_str!("../../kernels/radix_sort.cl"),
);

/// `kernels/skinning.cl`: linear blend skinning.
pub const SKINNING: KernelFile = plain(
    "kernels/skinning.cl",
    include_str!("../../kernels/skinning.cl"),
);

/// `kernels/ao.cl`: ambient occlusion from curvature.
pub const AO: KernelFile = plain("kernels/ao.cl", include_str!("../../kernels/ao.cl"));

/// The headers of both feature-line files: the common ones and isoline.h
/// (segment writes, rtsc's tested isolines).
const FEATURE_LINE_HEADERS: &[Source] = &[
    COMMON_HEADERS[0],
    COMMON_HEADERS[1],
    source!("common/isoline.h"),
];

/// `kernels/feature_lines.cl`: occluding and suggestive contours.
pub const FEATURE_LINES: KernelFile = KernelFile {
    name: "kernels/feature_lines.cl",
    source: include_str!("../../kernels/feature_lines.cl"),
    headers: FEATURE_LINE_HEADERS,
    includes: &[],
};

/// `kernels/feature_lines_curves.cl`: the curvature line families (ridges,
/// valleys, apparent ridges, highlights, isophotes, K = 0, H = 0, D_w κr = 0,
/// boundaries).
pub const FEATURE_LINES_CURVES: KernelFile = KernelFile {
    name: "kernels/feature_lines_curves.cl",
    source: include_str!("../../kernels/feature_lines_curves.cl"),
    headers: FEATURE_LINE_HEADERS,
    includes: &[],
};

/// `kernels/marching_cubes.cl`: the soup variants and gradient normals.
pub const MARCHING_CUBES: KernelFile = KernelFile {
    name: "kernels/marching_cubes.cl",
    source: include_str!("../../kernels/marching_cubes.cl"),
    headers: &[REAL_H, HASH_H, MC_EDGE_H, MC_CELL_H],
    includes: &[],
};

/// `kernels/marching_cubes_direct.cl`: direct numbering (its cell helpers
/// in `common/mc_direct.h`).
pub const MARCHING_CUBES_DIRECT: KernelFile = KernelFile {
    name: "kernels/marching_cubes_direct.cl",
    source: include_str!("../../kernels/marching_cubes_direct.cl"),
    headers: &[REAL_H, MC_EDGE_H, MC_CELL_H, MC_DIRECT_H],
    includes: &[],
};

/// `kernels/vertex_fusion.cl`: the soup's vertices fused.
pub const VERTEX_FUSION: KernelFile = KernelFile {
    name: "kernels/vertex_fusion.cl",
    source: include_str!("../../kernels/vertex_fusion.cl"),
    headers: &[REAL_H, HASH_H, MC_EDGE_H],
    includes: &[],
};

/// `kernels/edges.cl`: House & Li's edge-out and cap-out buffers.
pub const EDGES: KernelFile = plain("kernels/edges.cl", include_str!("../../kernels/edges.cl"));

/// `kernels/sdf_lines.cl`: curvature-directed strokes on a field (real.h
/// for `GID_OR_RETURN` and `SC_INLINE`, mc_edge.h for the edge rule).
pub const SDF_LINES: KernelFile = KernelFile {
    name: "kernels/sdf_lines.cl",
    source: include_str!("../../kernels/sdf_lines.cl"),
    headers: &[REAL_H, MC_EDGE_H],
    includes: &[],
};

/// `kernels/mesh_sdf.cl`: a mesh's signed distance field.
pub const MESH_SDF: KernelFile = plain(
    "kernels/mesh_sdf.cl",
    include_str!("../../kernels/mesh_sdf.cl"),
);

/// The headers of the files that read the bvh family's tree: the common
/// ones and bvh_tree.h (its node and box layout).
const BVH_TREE_HEADERS: &[Source] = &[COMMON_HEADERS[0], COMMON_HEADERS[1], BVH_TREE_H];

/// `kernels/bvh.cl`: a linear BVH over a mesh's faces and segment queries.
pub const BVH: KernelFile = KernelFile {
    name: "kernels/bvh.cl",
    source: include_str!("../../kernels/bvh.cl"),
    headers: BVH_TREE_HEADERS,
    includes: &[],
};

/// `kernels/intersections.cl`: where faces cross, over the bvh family's tree.
pub const INTERSECTIONS: KernelFile = KernelFile {
    name: "kernels/intersections.cl",
    source: include_str!("../../kernels/intersections.cl"),
    headers: BVH_TREE_HEADERS,
    includes: &[],
};

/// Every family's kernel file.
pub const ALL: &[KernelFile] = &[
    CURVATURE,
    SCAN,
    RADIX_SORT,
    SKINNING,
    AO,
    FEATURE_LINES,
    MARCHING_CUBES,
    MARCHING_CUBES_DIRECT,
    VERTEX_FUSION,
    EDGES,
    SDF_LINES,
    MESH_SDF,
    BVH,
    INTERSECTIONS,
];

/// A kernel file with the common headers and no includes.
const fn plain(name: &'static str, source: &'static str) -> KernelFile {
    KernelFile {
        name,
        source,
        headers: COMMON_HEADERS,
        includes: &[],
    }
}
