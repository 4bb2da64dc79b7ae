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
    let mut ring = vec![0u32; crate::spec::curvature::one_ring_len_bound(faces.len())];
    one_rings_into(faces, &mut off, &mut ring);
    (off, ring)
}

/// [`one_rings`] into given slices (e.g. device buffers mapped for writing):
/// `off` of length V+1 and `ring` of at least 3F entries; every element of
/// both is written (ring entries past 3F are zeroed). Face indices must be
/// below V.
pub fn one_rings_into(faces: &[[u32; 3]], off: &mut [u32], ring: &mut [u32]) {
    assert!(!off.is_empty() && ring.len() >= 3 * faces.len());
    off.fill(0);
    for f in faces {
        for &v in f {
            off[v as usize + 1] += 1;
        }
    }
    for i in 1..off.len() {
        off[i] += off[i - 1];
    }
    // off[v] is the start of v's list; used as its fill cursor, it ends at
    // the start of v + 1's, and the offsets are shifted back by one after.
    for (fi, f) in faces.iter().enumerate() {
        for (c, &v) in f.iter().enumerate() {
            let slot = &mut off[v as usize];
            ring[*slot as usize] = (fi * 3 + c) as u32;
            *slot += 1;
        }
    }
    off.copy_within(..off.len() - 1, 1);
    off[0] = 0;
    ring[3 * faces.len()..].fill(0);
}

/// The owning faces ([`max_face`]) read from one-ring lists: as each list is
/// in increasing face order, its last entry is the largest face using the
/// vertex. Writes `owner[v]` for every vertex (−1 for an empty list).
pub fn owners_from_rings(off: &[u32], ring: &[u32], owner: &mut [i32]) {
    for (v, o) in owner.iter_mut().enumerate() {
        let (a, b) = (off[v] as usize, off[v + 1] as usize);
        *o = if b > a { (ring[b - 1] / 3) as i32 } else { -1 };
    }
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

#[cfg(test)]
mod tests {
    use super::*;

    /// A small mesh with an unreferenced vertex (5), a vertex used twice by
    /// one face (degenerate face 3) and faces out of vertex order.
    fn faces() -> Vec<[u32; 3]> {
        vec![[0, 1, 2], [2, 1, 3], [4, 0, 2], [3, 3, 6], [6, 4, 0]]
    }

    #[test]
    fn one_rings_list_each_corner_once_in_face_order() {
        let f = faces();
        let (off, ring) = one_rings(7, &f);
        assert_eq!(off, [0, 3, 5, 8, 11, 13, 13, 15]);
        for v in 0..7 {
            let list = &ring[off[v] as usize..off[v + 1] as usize];
            let want: Vec<u32> = f
                .iter()
                .enumerate()
                .flat_map(|(fi, t)| {
                    (0..3)
                        .filter(move |&c| t[c] as usize == v)
                        .map(move |c| (fi * 3 + c) as u32)
                })
                .collect();
            assert_eq!(list, want, "vertex {v}");
        }
    }

    #[test]
    fn rings_into_dirty_slices_equal_fresh_ones_and_give_the_owners() {
        let f = faces();
        let (off, ring) = one_rings(7, &f);
        let mut off2 = vec![u32::MAX; 8];
        let mut ring2 = vec![u32::MAX; 3 * f.len() + 5];
        one_rings_into(&f, &mut off2, &mut ring2);
        assert_eq!(off2, off);
        assert_eq!(ring2[..ring.len()], ring[..]);
        assert!(ring2[ring.len()..].iter().all(|&e| e == 0));
        let mut owner = vec![7i32; 7];
        owners_from_rings(&off, &ring, &mut owner);
        let want: Vec<i32> = max_face(7, &f).iter().map(|&o| o as i32).collect();
        assert_eq!(owner, want);
        assert_eq!(owner[5], -1);
        assert_eq!(owner[3], 3);
    }
}
