//! Index-only structures of a triangle mesh, built once per topology and
//! reused for every pose (STYLE.md's "topology once, positions every frame"):
//! the one-ring lists of the curvature stage's gather variant
//! ([`one_rings`]), the owning face per vertex ([`max_face`], the CPU twin of
//! `curv_max_face`), and the area-weighted vertex normals the edges stage
//! projects for McGuire-Hughes caps ([`vertex_normals`], which also reads the
//! positions but is computed once per mesh by its callers).
//!
//! The edge and cap buffers of the edges stage are in [`super::edges`].

use super::Mesh;

/// Builds the one-ring lists: for each vertex, the (face·3 + corner) entries of
/// the faces using it, in increasing face order (CSR: offsets of length V+1,
/// [`crate::spec::curvature::one_ring_len_bound`] entries).
pub fn one_rings(nv: usize, faces: &[[u32; 3]]) -> (Vec<u32>, Vec<u32>) {
    let mut off = vec![0u32; nv + 1];
    for f in faces {
        for &v in f {
            off[v as usize + 1] += 1;
        }
    }
    for i in 0..nv {
        off[i + 1] += off[i];
    }
    let mut fill = off.clone();
    let mut ring = vec![0u32; crate::spec::curvature::one_ring_len_bound(faces.len())];
    for (fi, f) in faces.iter().enumerate() {
        for (c, &v) in f.iter().enumerate() {
            let slot = &mut fill[v as usize];
            ring[*slot as usize] = (fi * 3 + c) as u32;
            *slot += 1;
        }
    }
    (off, ring)
}

/// The largest face id using each vertex (−1 for a vertex no face uses): the
/// face whose edge seeds the vertex's initial tangent frame. CPU twin of the
/// kernel `curv_max_face` (an `atomic_max` per corner).
pub fn max_face(nv: usize, faces: &[[u32; 3]]) -> Vec<i64> {
    let mut owner = vec![-1i64; nv];
    for (f, face) in faces.iter().enumerate() {
        for &v in face {
            owner[v as usize] = owner[v as usize].max(f as i64);
        }
    }
    owner
}

/// Area-weighted unit vertex normals in f32 (unreferenced or degenerate
/// vertices get (0, 0, 0)): the normals McGuire-Hughes caps project.
pub fn vertex_normals(mesh: &Mesh) -> Vec<[f32; 3]> {
    let mut n = vec![[0f64; 3]; mesh.n_vertices()];
    for f in &mesh.faces {
        let [a, b, c] = f.map(|i| mesh.positions[i as usize]);
        let u = [b[0] - a[0], b[1] - a[1], b[2] - a[2]];
        let v = [c[0] - a[0], c[1] - a[1], c[2] - a[2]];
        let cr = [
            u[1] * v[2] - u[2] * v[1],
            u[2] * v[0] - u[0] * v[2],
            u[0] * v[1] - u[1] * v[0],
        ];
        for &i in f {
            for k in 0..3 {
                n[i as usize][k] += cr[k];
            }
        }
    }
    n.iter()
        .map(|v| {
            let l = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
            if l > 0.0 && l.is_finite() {
                [(v[0] / l) as f32, (v[1] / l) as f32, (v[2] / l) as f32]
            } else {
                [0.0; 3]
            }
        })
        .collect()
}
