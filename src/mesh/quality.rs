//! Mesh quality numbers used to compare isosurface variants (and to test
//! them): unique positions against vertices, faces that collapse, boundary
//! and non-manifold edges, the Euler characteristic.

use serde::Serialize;

/// What [`quality`] measured.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize)]
pub struct MeshQuality {
    /// Vertices in the vertex buffer.
    pub vertices: usize,
    /// Distinct positions among them (equal to `vertices` when fully fused).
    pub unique_positions: usize,
    /// Triangles.
    pub faces: usize,
    /// Triangles with a repeated index, two equal positions, or zero area.
    pub collapsed_faces: usize,
    /// Undirected edges (by index).
    pub edges: usize,
    /// Edges used by exactly one face.
    pub boundary_edges: usize,
    /// Edges used by three or more faces.
    pub nonmanifold_edges: usize,
    /// Vertices no face uses.
    pub unreferenced_vertices: usize,
    /// V − E + F over referenced vertices.
    pub euler: i64,
}

/// Measures `faces` over `positions` (any float type convertible to f64).
pub fn quality<P: Copy + Into<f64>>(positions: &[[P; 3]], faces: &[[u32; 3]]) -> MeshQuality {
    let to64 = |p: [P; 3]| p.map(Into::into);
    let mut bits: Vec<[u64; 3]> = positions
        .iter()
        .map(|&p| to64(p).map(|c: f64| (c + 0.0).to_bits()))
        .collect();
    bits.sort_unstable();
    bits.dedup();
    let mut collapsed = 0;
    let mut edges: Vec<u64> = Vec::with_capacity(faces.len() * 3);
    let mut used = vec![false; positions.len()];
    for f in faces {
        let p = f.map(|v| to64(positions[v as usize]));
        let u = [p[1][0] - p[0][0], p[1][1] - p[0][1], p[1][2] - p[0][2]];
        let w = [p[2][0] - p[0][0], p[2][1] - p[0][1], p[2][2] - p[0][2]];
        let zero_area =
            u[1] * w[2] == u[2] * w[1] && u[2] * w[0] == u[0] * w[2] && u[0] * w[1] == u[1] * w[0];
        if f[0] == f[1]
            || f[1] == f[2]
            || f[0] == f[2]
            || p[0] == p[1]
            || p[1] == p[2]
            || p[0] == p[2]
            || zero_area
        {
            collapsed += 1;
        }
        for i in 0..3 {
            used[f[i] as usize] = true;
            let (a, b) = (f[i], f[(i + 1) % 3]);
            if a != b {
                edges.push(((a.min(b) as u64) << 32) | a.max(b) as u64);
            }
        }
    }
    edges.sort_unstable();
    let (mut n_edges, mut boundary, mut nonmanifold) = (0, 0, 0);
    let mut i = 0;
    while i < edges.len() {
        let mut j = i;
        while j < edges.len() && edges[j] == edges[i] {
            j += 1;
        }
        n_edges += 1;
        match j - i {
            1 => boundary += 1,
            2 => {}
            _ => nonmanifold += 1,
        }
        i = j;
    }
    let referenced = used.iter().filter(|&&u| u).count();
    MeshQuality {
        vertices: positions.len(),
        unique_positions: bits.len(),
        faces: faces.len(),
        collapsed_faces: collapsed,
        edges: n_edges,
        boundary_edges: boundary,
        nonmanifold_edges: nonmanifold,
        unreferenced_vertices: positions.len() - referenced,
        euler: referenced as i64 - n_edges as i64 + faces.len() as i64,
    }
}
