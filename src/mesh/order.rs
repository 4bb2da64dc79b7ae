//! Memory order of a mesh's vertices and faces, for the cache locality of
//! the one-ring passes.
//!
//! A per-face pass reads the three vertices of each face, and a per-vertex
//! pass reads the faces around each vertex. When consecutive faces use
//! vertices far apart in memory (scanned meshes such as the Stanford bunny,
//! whose faces' vertex indices lie thousands apart), every face costs cache
//! misses (docs/performance.md gives the bunny's figures). [`LocalityOrder`]
//! renumbers the vertices along a Morton (Z-order) curve through the
//! bounding box, so that vertices near in space are near in memory, then
//! puts the faces in the order of their first vertex (a stable counting
//! sort). Computing on the reordered
//! mesh and mapping the results back ([`LocalityOrder::to_input`]) gives the
//! same values up to the rounding of sums taken in another order; at an
//! umbilic point, where every tangent is a principal direction, the
//! direction returned may differ, since it comes from the first frame.
//!
//! Meshes whose order is already local (generated grids, marching-cubes
//! output) are left as they are: [`LocalityOrder::scattered`] measures the
//! mean index spread of the faces first.

use super::Mesh;

/// How to order a mesh's vertices and faces in device memory.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum MeshOrder {
    /// Reorder when the input order is scattered ([`LocalityOrder::scattered`]).
    #[default]
    Auto,
    /// Keep the input order.
    Input,
    /// Always reorder along a Morton curve.
    Spatial,
}

impl MeshOrder {
    /// Every order, in `--help` order.
    pub const ALL: [MeshOrder; 3] = [MeshOrder::Auto, MeshOrder::Input, MeshOrder::Spatial];

    /// The name used on the command line and in stats.
    pub fn name(self) -> &'static str {
        match self {
            MeshOrder::Auto => "auto",
            MeshOrder::Input => "input",
            MeshOrder::Spatial => "spatial",
        }
    }
}

crate::spec::choice!(MeshOrder);

/// Scatter measures of a mesh's order (see [`LocalityOrder::scattered`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct OrderSpread {
    /// Mean over faces of (largest − smallest vertex index).
    pub face_span: f64,
    /// Mean over consecutive faces of |difference of their smallest vertex index|.
    pub face_jump: f64,
}

impl OrderSpread {
    /// Measures the order of `faces`.
    pub fn of(faces: &[[u32; 3]]) -> OrderSpread {
        if faces.is_empty() {
            return OrderSpread {
                face_span: 0.0,
                face_jump: 0.0,
            };
        }
        let (mut span, mut jump, mut prev) = (0u64, 0u64, None::<u32>);
        for f in faces {
            let (lo, hi) = (f[0].min(f[1]).min(f[2]), f[0].max(f[1]).max(f[2]));
            span += u64::from(hi - lo);
            if let Some(p) = prev {
                jump += u64::from(lo.abs_diff(p));
            }
            prev = Some(lo);
        }
        let n = faces.len() as f64;
        OrderSpread {
            face_span: span as f64 / n,
            face_jump: jump as f64 / (n - 1.0).max(1.0),
        }
    }
}

/// A renumbering of a mesh's vertices and faces for locality.
#[derive(Clone, Debug, PartialEq)]
pub struct LocalityOrder {
    /// For each new vertex index, the input vertex it holds.
    pub input_vertex: Vec<u32>,
    /// For each new face index, the input face it holds.
    pub input_face: Vec<u32>,
}

impl LocalityOrder {
    /// The spread above which [`MeshOrder::Auto`] reorders: a mean face span
    /// or face-to-face jump of more than 4·√V indices. A regular grid of
    /// rows of about √V vertices spans about √V; the Stanford bunny as
    /// scanned spans about 20·√V (3,800 indices).
    pub fn scattered(nv: usize, faces: &[[u32; 3]]) -> bool {
        let s = OrderSpread::of(faces);
        let bound = 4.0 * (nv as f64).sqrt();
        s.face_span > bound || s.face_jump > bound
    }

    /// The order `order` asks for on `mesh`, or `None` to keep the input
    /// order (asked for, or already local under [`MeshOrder::Auto`]).
    pub fn choose(mesh: &Mesh, order: MeshOrder) -> Option<LocalityOrder> {
        match order {
            MeshOrder::Input => None,
            MeshOrder::Auto if !Self::scattered(mesh.n_vertices(), &mesh.faces) => None,
            _ => Some(Self::spatial(mesh)),
        }
    }

    /// Vertices along a Morton curve of 21 bits per axis through the
    /// bounding box (ties keep the input order), faces by their smallest new
    /// vertex index (stable). Positions must be finite ([`Mesh::validate`]).
    pub fn spatial(mesh: &Mesh) -> LocalityOrder {
        let nv = mesh.n_vertices();
        let (mut lo, mut hi) = ([f64::INFINITY; 3], [f64::NEG_INFINITY; 3]);
        for p in &mesh.positions {
            for k in 0..3 {
                lo[k] = lo[k].min(p[k]);
                hi[k] = hi[k].max(p[k]);
            }
        }
        const CELLS: f64 = ((1u32 << 21) - 1) as f64;
        // Per axis: cells per unit length (0 for a flat axis, so no NaN).
        let inv: [f64; 3] = std::array::from_fn(|k| {
            let ext = hi[k] - lo[k];
            if ext > 0.0 && ext.is_finite() {
                CELLS / ext
            } else {
                0.0
            }
        });
        let mut keyed: Vec<(u64, u32)> = mesh
            .positions
            .iter()
            .enumerate()
            .map(|(i, p)| {
                // A NaN (an infinite extent times 0) converts to 0.
                let q: [u64; 3] =
                    std::array::from_fn(|k| ((p[k] - lo[k]) * inv[k]).clamp(0.0, CELLS) as u64);
                (
                    spread3(q[0]) | spread3(q[1]) << 1 | spread3(q[2]) << 2,
                    i as u32,
                )
            })
            .collect();
        keyed.sort_unstable();
        let input_vertex: Vec<u32> = keyed.into_iter().map(|(_, i)| i).collect();
        let new_of = inverse(&input_vertex);
        // Counting sort of the faces by their smallest new vertex index.
        let key = |f: &[u32; 3]| f.map(|v| new_of[v as usize]).into_iter().min().unwrap_or(0);
        let mut start = vec![0u32; nv + 1];
        for f in &mesh.faces {
            start[key(f) as usize + 1] += 1;
        }
        for i in 0..nv {
            start[i + 1] += start[i];
        }
        let mut input_face = vec![0u32; mesh.n_faces()];
        for (fi, f) in mesh.faces.iter().enumerate() {
            let s = &mut start[key(f) as usize];
            input_face[*s as usize] = fi as u32;
            *s += 1;
        }
        LocalityOrder {
            input_vertex,
            input_face,
        }
    }

    /// The mesh in this order: positions permuted, faces permuted and
    /// renumbered (each face keeps its corner order, so its orientation).
    ///
    /// # Panics
    ///
    /// If `mesh` is not the mesh this order was made for (other vertex or
    /// face counts); the same holds for [`LocalityOrder::frame_faces`] and,
    /// for the length of `values`, [`LocalityOrder::to_input`].
    pub fn apply(&self, mesh: &Mesh) -> Mesh {
        assert!(
            mesh.n_vertices() == self.input_vertex.len() && mesh.n_faces() == self.input_face.len(),
            "LocalityOrder::apply: the order was made for another mesh"
        );
        let new_of = inverse(&self.input_vertex);
        Mesh {
            positions: self
                .input_vertex
                .iter()
                .map(|&i| mesh.positions[i as usize])
                .collect(),
            faces: self
                .input_face
                .iter()
                .map(|&f| mesh.faces[f as usize].map(|v| new_of[v as usize]))
                .collect(),
            normals: mesh
                .normals
                .as_ref()
                .map(|n| self.input_vertex.iter().map(|&i| n[i as usize]).collect()),
        }
    }

    /// For each new vertex, the new index of the face that seeds its initial
    /// tangent frame in the input order (the largest input face id using it,
    /// [`super::topology::max_face`]; −1 for none), so that the reordered
    /// mesh's principal directions keep their input-order signs. `input` is
    /// the mesh this order was made for.
    pub fn frame_faces(&self, input: &Mesh) -> Vec<i32> {
        assert!(
            input.n_vertices() == self.input_vertex.len()
                && input.n_faces() == self.input_face.len(),
            "LocalityOrder::frame_faces: the order was made for another mesh"
        );
        let owner = super::topology::max_face(input.n_vertices(), &input.faces);
        let new_face = inverse(&self.input_face);
        self.input_vertex
            .iter()
            .map(|&v| match owner[v as usize] {
                f if f >= 0 => new_face[f as usize] as i32,
                _ => -1,
            })
            .collect()
    }

    /// Per-vertex values computed on the reordered mesh, back in the
    /// input's vertex order.
    pub fn to_input<T: Copy + Default>(&self, values: &[T]) -> Vec<T> {
        assert_eq!(
            values.len(),
            self.input_vertex.len(),
            "LocalityOrder::to_input: one value per vertex"
        );
        let mut out = vec![T::default(); values.len()];
        for (new, &old) in self.input_vertex.iter().enumerate() {
            out[old as usize] = values[new];
        }
        out
    }
}

/// The inverse of a permutation: for each input index, its new index.
fn inverse(input_of: &[u32]) -> Vec<u32> {
    let mut new_of = vec![0u32; input_of.len()];
    for (new, &old) in input_of.iter().enumerate() {
        new_of[old as usize] = new as u32;
    }
    new_of
}

/// The low 21 bits of `x` spread to every third bit (bit i → bit 3i).
fn spread3(x: u64) -> u64 {
    let mut x = x & 0x1f_ffff;
    x = (x | x << 32) & 0x1f_0000_0000_ffff;
    x = (x | x << 16) & 0x1f_0000_ff00_00ff;
    x = (x | x << 8) & 0x100f_00f0_0f00_f00f;
    x = (x | x << 4) & 0x10c3_0c30_c30c_30c3;
    x = (x | x << 2) & 0x1249_2492_4924_9249;
    x
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn spread3_puts_bit_i_at_3i() {
        for i in 0..21 {
            assert_eq!(spread3(1 << i), 1 << (3 * i), "bit {i}");
        }
        assert_eq!(spread3(u64::MAX), 0x1249_2492_4924_9249);
    }

    /// A grid of `n`×`n` vertices in row order, two triangles per cell.
    fn grid(n: u32) -> Mesh {
        let positions = (0..n * n)
            .map(|i| [(i % n) as f64, (i / n) as f64, 0.0])
            .collect();
        let mut faces = Vec::new();
        for y in 0..n - 1 {
            for x in 0..n - 1 {
                let a = y * n + x;
                faces.push([a, a + 1, a + n + 1]);
                faces.push([a, a + n + 1, a + n]);
            }
        }
        Mesh {
            positions,
            faces,
            normals: None,
        }
    }

    #[test]
    fn a_row_ordered_grid_is_local_and_a_shuffled_one_is_not() {
        let g = grid(64);
        assert!(!LocalityOrder::scattered(g.n_vertices(), &g.faces));
        assert!(LocalityOrder::choose(&g, MeshOrder::Auto).is_none());
        // Reverse the bits of the vertex indices: neighbours land far apart.
        let perm: Vec<u32> = (0..4096u32).map(|i| i.reverse_bits() >> 20).collect();
        let shuffled = Mesh {
            positions: (0..4096).map(|i| g.positions[perm[i] as usize]).collect(),
            faces: g
                .faces
                .iter()
                .map(|f| f.map(|v| perm[v as usize]))
                .collect(),
            normals: None,
        };
        assert!(LocalityOrder::scattered(4096, &shuffled.faces));
        let o = LocalityOrder::choose(&shuffled, MeshOrder::Auto).expect("reordered");
        let r = o.apply(&shuffled);
        let (before, after) = (OrderSpread::of(&shuffled.faces), OrderSpread::of(&r.faces));
        assert!(
            after.face_span < before.face_span / 10.0 && after.face_jump < 2.0,
            "{before:?} -> {after:?}"
        );
        assert!(!LocalityOrder::scattered(4096, &r.faces));
    }

    #[test]
    fn reordering_keeps_every_face_and_maps_values_back() {
        let mut m = grid(9);
        m.positions.push([0.5, 0.5, 7.0]); // unreferenced
        m.faces.push([3, 3, 4]); // degenerate, kept
        let o = LocalityOrder::spatial(&m);
        let r = o.apply(&m);
        assert_eq!(r.n_vertices(), m.n_vertices());
        assert_eq!(r.n_faces(), m.n_faces());
        r.validate("reordered").unwrap();
        // Each new face is the input face it names, vertex for vertex and in
        // the same corner order.
        for (nf, &of) in o.input_face.iter().enumerate() {
            let back = r.faces[nf].map(|v| o.input_vertex[v as usize]);
            assert_eq!(back, m.faces[of as usize]);
        }
        // Faces are sorted by their smallest vertex.
        let mins: Vec<u32> = r.faces.iter().map(|f| *f.iter().min().unwrap()).collect();
        assert!(mins.windows(2).all(|w| w[0] <= w[1]));
        // A per-vertex value (here the position itself) comes back in input order.
        assert_eq!(o.to_input(&r.positions), m.positions);
        // Deterministic.
        assert_eq!(LocalityOrder::spatial(&m), o);
    }

    #[test]
    fn flat_huge_tiny_and_single_point_meshes_are_ordered_without_nan() {
        for s in [1e-300, 1.0, 1e300] {
            let mut m = grid(5);
            for p in &mut m.positions {
                *p = [p[0] * s, 0.0, p[1] * s];
            }
            let o = LocalityOrder::spatial(&m);
            assert_eq!(o.to_input(&o.apply(&m).positions), m.positions, "scale {s}");
        }
        // Opposite huge coordinates: the extent overflows to infinity.
        let m = Mesh {
            positions: vec![[-1e308, 0.0, 0.0], [1e308, 0.0, 0.0], [0.0, 1.0, 0.0]],
            faces: vec![[0, 1, 2]],
            normals: None,
        };
        let o = LocalityOrder::spatial(&m);
        assert_eq!(o.apply(&m).n_faces(), 1);
        let one = Mesh {
            positions: vec![[2.0; 3]; 3],
            faces: vec![[0, 1, 2]],
            normals: None,
        };
        assert_eq!(LocalityOrder::spatial(&one).input_vertex, vec![0, 1, 2]);
    }
}
