//! CPU reference of `kernels/vertex_fusion.cl`: turns the marching-cubes
//! triangle soup into an indexed mesh with shared vertices, with the same
//! steps as the device (Griffin et al. 2012, §3.4):
//! `fuse_keys` (hash of the position, or the exact edge/point key) →
//! stable sort of (key, soup index) → `fuse_index` (binary search to the first
//! equal key, then walk forward comparing positions) → `fuse_triangles`
//! (triangles whose fused corners repeat are dropped; referenced vertices
//! marked) → compaction (`fuse_compact_vertices`, `fuse_compact_faces`).
//!
//! The representative of a set of equal positions is the lowest soup index,
//! so the hash and the exact variant give the same mesh, vertex for vertex.

use crate::spec::vertex_fusion::Fusion;

/// One vertex of the triangle soup that marching cubes writes
/// ([`mc_triangles`](super::marching_cubes::mc_triangles)) and fusion
/// reads: its position in index space (voxel units; world = origin +
/// spacing × p) and its exact key: `4g + axis` for a vertex inside the edge
/// of axis `axis` starting at grid point `g`, `4g + 3` for a vertex at grid
/// point `g`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SoupVertex {
    /// Index-space position.
    pub p: [f32; 3],
    /// Exact key (u64; the device uses u32 and checks that it fits).
    pub key: u64,
}

/// The 32-bit position hash (same integer mix as the kernel's `fuse_hash`).
pub fn fuse_hash(p: [f32; 3]) -> u32 {
    let mut h = p[0].to_bits().wrapping_mul(0x9E37_79B1);
    h ^= p[1].to_bits();
    h = (h ^ (h >> 15)).wrapping_mul(0x85EB_CA6B);
    h ^= p[2].to_bits();
    h = (h ^ (h >> 13)).wrapping_mul(0xC2B2_AE35);
    h ^ (h >> 16)
}

/// An indexed triangle mesh in index space, as fusion leaves it.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Fused {
    /// Unique vertex positions (index space).
    pub positions: Vec<[f32; 3]>,
    /// Triangles.
    pub faces: Vec<[u32; 3]>,
    /// Triangles dropped: two fused corners were the same vertex, or the
    /// triangle was cancelled with an opposite twin (a zero-thickness sheet).
    pub dropped: usize,
}

/// Soup vertex → representative soup vertex (`fuse_index`), given the soup
/// keys sorted stably together with their soup indices.
pub fn fuse_index(
    soup: &[SoupVertex],
    keys: &[u64],
    sorted: &[(u64, u32)],
    compare_positions: bool,
) -> Vec<u32> {
    (0..soup.len())
        .map(|v| {
            let k = keys[v];
            let mut j = sorted.partition_point(|&(s, _)| s < k);
            if !compare_positions {
                return sorted[j].1;
            }
            loop {
                let cand = sorted[j].1;
                if soup[cand as usize].p == soup[v].p {
                    return cand;
                }
                j += 1;
            }
        })
        .collect()
}

/// Fuses a soup with the given variant (see the module docs for the steps).
pub fn fuse(soup: &[SoupVertex], fusion: Fusion) -> Fused {
    if fusion == Fusion::None {
        return Fused {
            positions: soup.iter().map(|s| s.p).collect(),
            faces: (0..soup.len() as u32 / 3)
                .map(|t| [3 * t, 3 * t + 1, 3 * t + 2])
                .collect(),
            dropped: 0,
        };
    }
    // fuse_keys
    let keys: Vec<u64> = soup
        .iter()
        .map(|s| match fusion {
            Fusion::Hash => fuse_hash(s.p) as u64,
            _ => s.key,
        })
        .collect();
    // radix_sort (stable)
    let mut sorted: Vec<(u64, u32)> = keys
        .iter()
        .enumerate()
        .map(|(i, &k)| (k, i as u32))
        .collect();
    sorted.sort_by_key(|&(k, _)| k);
    let rep = fuse_index(soup, &keys, &sorted, fusion == Fusion::Hash);
    let positions: Vec<[f32; 3]> = soup.iter().map(|s| s.p).collect();
    let faces: Vec<[u32; 3]> = rep.chunks(3).map(|r| [r[0], r[1], r[2]]).collect();
    fuse_finish(&positions, &faces)
}

/// The steps after `fuse_index`, shared with direct numbering: triangles
/// (`faces`, indices into `positions`) whose corners repeat are dropped,
/// opposite twins lying in a grid plane cancelled, and the vertices still
/// used compacted in index order (`fuse_triangles`, `fuse_candidates`,
/// `fuse_cancel`, `fuse_mark`, `fuse_compact_vertices`, `fuse_compact_faces`).
pub fn fuse_finish(positions: &[[f32; 3]], faces: &[[u32; 3]]) -> Fused {
    // fuse_triangles
    let nt = faces.len();
    let tri = |t: usize| faces[t];
    let mut keep = vec![false; nt];
    let mut cand = Vec::new();
    for (t, kt) in keep.iter_mut().enumerate() {
        let f = tri(t);
        *kt = f[0] != f[1] && f[1] != f[2] && f[0] != f[2];
        let p = f.map(|v| positions[v as usize]);
        if *kt
            && (0..3)
                .any(|a| p[0][a] == p[1][a] && p[1][a] == p[2][a] && p[0][a] == p[0][a].floor())
        {
            cand.push(t);
        }
    }
    // fuse_candidates + fuse_cancel: group candidates by vertex set (in
    // soup order), drop the first min(n+, n−) of each winding.
    let mut groups: std::collections::BTreeMap<[u32; 3], Vec<(usize, bool)>> = Default::default();
    for &t in &cand {
        let (set, even) = tri_set(tri(t));
        groups.entry(set).or_default().push((t, even));
    }
    for g in groups.values() {
        let plus = g.iter().filter(|e| e.1).count();
        let pairs = plus.min(g.len() - plus);
        for even in [true, false] {
            for &(t, _) in g.iter().filter(|e| e.1 == even).take(pairs) {
                keep[t] = false;
            }
        }
    }
    // fuse_mark
    let mut referenced = vec![false; positions.len()];
    let mut kept = Vec::new();
    for (t, &k) in keep.iter().enumerate() {
        if k {
            for v in tri(t) {
                referenced[v as usize] = true;
            }
            kept.push(tri(t));
        }
    }
    let dropped = nt - kept.len();
    // fuse_compact_vertices / fuse_compact_faces
    let mut new_id = vec![u32::MAX; positions.len()];
    let mut kept_positions = Vec::new();
    for (v, &r) in referenced.iter().enumerate() {
        if r {
            new_id[v] = kept_positions.len() as u32;
            kept_positions.push(positions[v]);
        }
    }
    let faces = kept.iter().map(|f| f.map(|v| new_id[v as usize])).collect();
    Fused {
        positions: kept_positions,
        faces,
        dropped,
    }
}

pub use crate::spec::vertex_fusion::tri_set;
