//! Shared types of the `vertex_fusion` family (see [`crate::spec`]): the
//! variant ([`Fusion`]), the counts of one fusion ([`FusionCounts`]) and the
//! bounds that size its scratch and outputs from the soup size.
//!
//! Mirrors in `kernels/vertex_fusion.cl` (buffer table in its header, S soup
//! vertices, T = S/3 soup triangles): `rep`, `ref`, `vert_id` `uint[S]`;
//! `keep`, `cand`, `cand_off`, `face_off` `uint[T]` ([`soup_triangles`]);
//! `ckeys`, `cvals` `uint[C]`, C ≤ [`cancel_candidates_bound`]; `out_pos`
//! `float[3V]`, V ≤ [`fused_vertices_bound`]; `out_faces` `uint[3F]`,
//! F ≤ [`fused_faces_bound`]. `fuse_index`'s `compare_positions` is 1 for
//! [`Fusion::Hash`]; `mc_triangles`' `mode` is [`Fusion::code`]. Scalar
//! arguments only: no parameter struct crosses.

/// How the vertices of an isosurface are shared between its triangles.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Fusion {
    /// Exact and the fastest: no soup; each vertex is made once by the voxel
    /// edge it lies on and numbered by a scan over per-row counts, as
    /// Flying Edges (Schroeder, Maynard and Geveci 2015) does.
    Direct,
    /// Exact: each vertex keyed by the voxel edge (or grid point) it lies on.
    Edge,
    /// Griffin et al.'s method: 32-bit hash of the position bits, radix sort,
    /// collisions resolved by comparing positions.
    Hash,
    /// No fusion: the triangle soup, three vertices per triangle.
    None,
}

impl Fusion {
    /// All variants, in the order of the CLI, tables and benches.
    pub const ALL: [Fusion; 4] = [Fusion::Direct, Fusion::Edge, Fusion::Hash, Fusion::None];

    /// Name used on the command line, in stats and in bench ids.
    pub fn name(self) -> &'static str {
        match self {
            Fusion::Direct => "direct",
            Fusion::Hash => "hash",
            Fusion::Edge => "edge",
            Fusion::None => "none",
        }
    }

    /// `mc_triangles`' `mode` argument: which key it writes per soup vertex
    /// (0 none, 1 the position hash, 2 the exact edge key). [`Fusion::Direct`]
    /// makes no soup and does not run `mc_triangles` (0).
    pub fn code(self) -> u32 {
        match self {
            Fusion::None | Fusion::Direct => 0,
            Fusion::Hash => 1,
            Fusion::Edge => 2,
        }
    }
}

super::named_choice!(Fusion, "vertex fusion");

/// Counts of one fusion.
#[derive(Clone, Copy, Debug, Default, serde::Serialize)]
pub struct FusionCounts {
    /// Unique vertices kept.
    pub vertices: usize,
    /// Triangles kept.
    pub faces: usize,
    /// Triangles dropped: two fused corners were the same vertex, or the
    /// triangle was cancelled with an opposite twin.
    pub dropped: usize,
}

/// Bytes of device memory direct numbering needs beyond the volume, for
/// `grid_rows` grid rows, `vertices` edge vertices, `hits` grid-point hits,
/// `triangles` triangles and room for `side_records` triangles with a hit
/// corner in a grid plane: row summaries and counts (4 each per row),
/// splits (2 each), trims (3 each: range and chunk mask), the recount (1),
/// hit keys (4 bytes per hit), the list (3 words per record), positions,
/// faces, and the clean-up of vertex fusion when there are hits or
/// non-finite voxels (`cleanup`).
pub fn direct_device_bytes_bound(
    grid_rows: usize,
    vertices: usize,
    hits: usize,
    triangles: usize,
    side_records: usize,
    cleanup: bool,
) -> u64 {
    let slots = (vertices + hits) as u64;
    let t = triangles as u64;
    let mut b =
        56 * grid_rows as u64 + 4 * hits as u64 + 12 * side_records as u64 + 12 * slots + 12 * t;
    if cleanup {
        // rep is the faces buffer; referenced + vert_id per slot, and direct
        // numbering's own marks of the check for unused vertices; keep,
        // face_off, cand, cand_off per triangle; candidate keys and their
        // sort; the compacted outputs.
        b += 12 * slots + 16 * t + 16 * t + 12 * slots + 12 * t;
    }
    b
}

/// Soup triangles of `soup_vertices` soup vertices (three each): the length
/// of the per-triangle flags and offsets.
pub fn soup_triangles(soup_vertices: usize) -> usize {
    soup_vertices / 3
}

/// Most unique vertices a fusion of `soup_vertices` can keep (every soup
/// vertex its own).
pub fn fused_vertices_bound(soup_vertices: usize) -> usize {
    soup_vertices
}

/// Most faces a fusion of `soup_vertices` can keep (no triangle dropped).
pub fn fused_faces_bound(soup_vertices: usize) -> usize {
    soup_triangles(soup_vertices)
}

/// Most twin-cancellation candidates (`ckeys`, `cvals`): at most one per
/// soup triangle.
pub fn cancel_candidates_bound(soup_vertices: usize) -> usize {
    soup_triangles(soup_vertices)
}

/// Bytes a device fusion of `soup_vertices` soup vertices needs (scratch,
/// outputs and the sort's scratch), for the caller's memory check.
pub fn device_bytes_bound(soup_vertices: usize) -> u64 {
    // rep, referenced, vert_id: 4n each; keep, face_off, cand, cand_off:
    // 4n/3 each (candidate keys at most as many); outputs at most 12n + 4n;
    // sort scratch ~ 8n + histograms.
    (12 + 6 + 3 + 16 + 9) * soup_vertices as u64
}

/// A triangle's sorted vertex set and whether its winding is an even
/// permutation of it (same rule as the kernel's `tri_set`).
pub fn tri_set(f: [u32; 3]) -> ([u32; 3], bool) {
    let mut s = f;
    s.sort_unstable();
    let even = if f[0] == s[0] {
        f[1] < f[2]
    } else if f[1] == s[0] {
        f[2] < f[0]
    } else {
        f[0] < f[1]
    };
    (s, even)
}

#[cfg(test)]
mod tests {
    use crate::spec::Choice;
    use crate::spec::{ao::AoMode, curvature, marching_cubes, radix_sort, scan};

    /// `name()`, `Display`, `FromStr` and the command line's names
    /// ([`Choice`]) agree.
    fn names_agree<T>(all: &[T], name: fn(&T) -> &'static str)
    where
        T: Choice + std::fmt::Display + std::str::FromStr + PartialEq + std::fmt::Debug,
    {
        assert_eq!(all.len(), T::all().len());
        for (v, cli) in all.iter().zip(T::all()) {
            assert_eq!(cli.label(), name(v));
            assert_eq!(v.to_string(), name(v));
            assert!(name(v).parse::<T>().ok().as_ref() == Some(v));
        }
        assert!("no such choice".parse::<T>().is_err());
    }

    #[test]
    fn option_enum_names() {
        names_agree(&super::Fusion::ALL, |v| v.name());
        names_agree(&AoMode::ALL, |v| v.name());
        names_agree(&curvature::Accumulate::ALL, |v| v.name());
        names_agree(&curvature::Precision::ALL, |v| v.name());
        names_agree(&curvature::Compat::ALL, |v| v.name());
        names_agree(&marching_cubes::IsoNormals::ALL, |v| v.name());
        names_agree(&curvature::AccumulateChoice::ALL, |v| v.name());
    }

    #[test]
    fn splits_and_bounds() {
        for n in [0, 1, 255, 256, 257, 4096 * 256, 4096 * 256 + 1, 10_000_000] {
            let (c, k) = scan::chunking(n);
            assert!(k <= scan::MAX_CHUNKS && (n == 0 || (c >= scan::MIN_CHUNK && c * k >= n)));
            let (b, g) = radix_sort::blocking(n);
            assert!(g <= radix_sort::MAX_BLOCKS && (n == 0 || (b >= radix_sort::MIN_BLOCK)));
            assert_eq!(radix_sort::histogram_len_bound(n), radix_sort::RADIX * g);
        }
        assert_eq!(marching_cubes::edge_key_bits(8), Some(5));
        assert_eq!(marching_cubes::edge_key_bits(1 << 30), Some(32));
        assert_eq!(marching_cubes::edge_key_bits((1 << 30) + 1), None);
        assert_eq!(super::fused_faces_bound(9), 3);
    }
}

crate::spec::kernels::kernel_entries! {
    /// The entry points of `kernels/vertex_fusion.cl`.
    pub enum FuseKernel {
        /// Each soup vertex to the first of its equal keys.
        Index = "fuse_index",
        /// Counters reset.
        Clear = "fuse_clear",
        /// Triangles re-indexed, collapsed ones dropped.
        Triangles = "fuse_triangles",
        /// Triangles that may have an opposite-wound twin.
        Candidates = "fuse_candidates",
        /// Twins cancelled.
        Cancel = "fuse_cancel",
        /// Vertices still used.
        Mark = "fuse_mark",
        /// Used vertices, compacted.
        CompactVertices = "fuse_compact_vertices",
        /// Kept faces, compacted.
        CompactFaces = "fuse_compact_faces",
    }
}
