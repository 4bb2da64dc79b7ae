//! Triangle meshes: the index-based data type, loaders (OBJ, PLY, OFF),
//! validation and welding; animated sources: glTF skins ([`skinned`]),
//! flipbook sequences ([`flipbook`]) and libigl LBS sets ([`libigl`]).
//!
//! Positions are kept in `f64` on the host so that a mesh far from the origin
//! or at an extreme scale survives until the stage that uploads it, which
//! centres and scales it before rounding to the device's precision.

pub mod barycentric;
pub mod edges;
pub mod feature_size;
pub mod flipbook;
mod generate;
pub mod libigl;
mod load;
pub mod mesh_sdf;
pub mod order;
mod quality;
pub mod skinned;
mod solids;
pub mod topology;

pub use generate::*;
pub use load::{LoadOptions, NormalsSource, header_counts, load, load_several};
pub use quality::{MeshQuality, quality};
pub use solids::*;

use crate::error::{Error, Result};

/// An indexed triangle mesh. Faces index into `positions`; polygons from the
/// input are fan-triangulated by the loaders.
///
/// Degenerate faces, duplicate faces, unreferenced vertices, boundaries and
/// non-manifold edges are valid: stages must cope with them. What is *not*
/// valid (and rejected by [`Mesh::validate`]): no faces, an index out of range,
/// or a non-finite coordinate.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Mesh {
    /// Vertex positions.
    pub positions: Vec<[f64; 3]>,
    /// Triangles, counter-clockwise seen from outside.
    pub faces: Vec<[u32; 3]>,
    /// The vertex normals the file stored, one per vertex (OBJ `vn` lines
    /// in order, PLY `nx ny nz`), as trimesh2 2.16 reads them: `None` when
    /// the file stores none, or not exactly one per vertex. Kept as stored
    /// (not normalized); [`Mesh::check_normals`] says whether they can be
    /// used.
    pub normals: Option<Vec<[f32; 3]>>,
}

impl Mesh {
    /// Builds a mesh and validates it; `source` names where it came from in errors.
    pub fn new(positions: Vec<[f64; 3]>, faces: Vec<[u32; 3]>, source: &str) -> Result<Self> {
        let m = Mesh {
            positions,
            faces,
            normals: None,
        };
        m.validate(source)?;
        Ok(m)
    }

    /// Number of vertices.
    pub fn n_vertices(&self) -> usize {
        self.positions.len()
    }

    /// Number of triangles.
    pub fn n_faces(&self) -> usize {
        self.faces.len()
    }

    /// The meshes as one: their vertices and faces in order, each mesh's
    /// indices offset by the vertices before it; `what` names the result
    /// in errors.
    ///
    /// # Errors
    /// More vertices in all than 32-bit indices address.
    pub fn concat(meshes: &[Mesh], what: &str) -> crate::error::Result<Mesh> {
        let total: usize = meshes.iter().map(Mesh::n_vertices).sum();
        if total > u32::MAX as usize {
            return Err(crate::error::Error::InvalidArgument(format!(
                "{what}: {total} vertices in all, more than 32-bit indices address"
            )));
        }
        let mut out = Mesh {
            positions: Vec::with_capacity(total),
            faces: Vec::new(),
            normals: None,
        };
        for m in meshes {
            let base = out.positions.len() as u32;
            out.positions.extend_from_slice(&m.positions);
            out.faces
                .extend(m.faces.iter().map(|f| f.map(|v| v + base)));
        }
        // Stored normals survive only where every mesh has them.
        if meshes.iter().all(|m| m.normals.is_some()) {
            out.normals = Some(
                meshes
                    .iter()
                    .flat_map(|m| m.normals.iter().flatten().copied())
                    .collect(),
            );
        }
        Ok(out)
    }

    /// Rejects what no stage can work with: no faces, indices out of range,
    /// non-finite coordinates, or more elements than 32-bit indices address.
    pub fn validate(&self, source: &str) -> Result<()> {
        check_faces(self.positions.len(), &self.faces, source)?;
        check_positions(&self.positions, source)?;
        match &self.normals {
            Some(n) if n.len() != self.positions.len() => Err(Error::input(
                source,
                "normals",
                format!(
                    "{} stored normals for {} vertices (one per vertex is needed)",
                    n.len(),
                    self.positions.len()
                ),
            )),
            _ => Ok(()),
        }
    }

    /// Refuses stored normals that no curvature can start from: a zero or
    /// non-finite normal at a vertex some face uses, naming the vertex.
    /// Normals of any other length are scaled to unit length where they are
    /// used; normals that point against the faces' orientation are used as
    /// they are, as trimesh2 uses them ([`Mesh::normals_against_faces`]
    /// counts them).
    pub fn check_normals(&self, source: &str) -> Result<()> {
        let Some(normals) = &self.normals else {
            return Ok(());
        };
        let used = self.referenced();
        for (i, n) in normals.iter().enumerate() {
            // In f32, as the device takes them: a length it cannot square is
            // none.
            let l2 = n[0] * n[0] + n[1] * n[1] + n[2] * n[2];
            if used[i] && !(l2.is_finite() && l2 >= f32::MIN_POSITIVE) {
                return Err(Error::input(
                    source,
                    format!("vertex {i}"),
                    format!(
                        "its stored normal ({}, {}, {}) has no direction; fix the file, or \
                         compute the normals from the faces instead (normals \"computed\")",
                        n[0], n[1], n[2]
                    ),
                ));
            }
        }
        Ok(())
    }

    /// How many used vertices' stored normals point against the
    /// area-weighted normal of their faces (0 without stored normals).
    pub fn normals_against_faces(&self) -> usize {
        let Some(stored) = &self.normals else {
            return 0;
        };
        let computed = topology::vertex_normals(self);
        stored
            .iter()
            .zip(&computed)
            .filter(|(s, c)| {
                let d: f32 = (0..3).map(|k| s[k] * c[k]).sum();
                d < 0.0
            })
            .count()
    }

    /// Merges vertices with bit-identical positions (as in unwelded exports
    /// that split vertices per corner). Returns the welded mesh and, for each
    /// old vertex, its new index. The first occurrence of a position keeps its
    /// relative order, so welding an already welded mesh changes nothing.
    pub fn weld(&self) -> (Mesh, Vec<u32>) {
        use std::collections::HashMap;
        let mut map: HashMap<[u64; 3], u32> = HashMap::with_capacity(self.positions.len());
        let mut positions = Vec::with_capacity(self.positions.len());
        let mut remap = Vec::with_capacity(self.positions.len());
        for p in &self.positions {
            // +0.0 and -0.0 are the same point: normalise the sign of zero.
            let key = p.map(|c| if c == 0.0 { 0u64 } else { c.to_bits() });
            let idx = *map.entry(key).or_insert_with(|| {
                positions.push(*p);
                (positions.len() - 1) as u32
            });
            remap.push(idx);
        }
        let faces = self
            .faces
            .iter()
            .map(|f| f.map(|v| remap[v as usize]))
            .collect();
        // A welded vertex's stored normal is the sum of its copies' (unit
        // length where it is used).
        let normals = self.normals.as_ref().map(|stored| {
            let mut sum = vec![[0f32; 3]; positions.len()];
            for (n, &to) in stored.iter().zip(&remap) {
                for k in 0..3 {
                    sum[to as usize][k] += n[k];
                }
            }
            sum
        });
        (
            Mesh {
                positions,
                faces,
                normals,
            },
            remap,
        )
    }

    /// Whether no two faces share a vertex (and there are two or more): a
    /// triangle soup, as STL files and some exports give, on which
    /// curvature has no one-ring and line families find nothing until the
    /// vertices are welded ([`Mesh::weld`]).
    pub fn shares_no_vertex(&self) -> bool {
        let mut used = vec![false; self.n_vertices()];
        for f in &self.faces {
            for &v in f {
                if std::mem::replace(&mut used[v as usize], true) {
                    // Used by an earlier face (or twice by this one).
                    return false;
                }
            }
        }
        self.faces.len() > 1
    }

    /// Why a mesh shared by no two faces draws no lines, and what to do,
    /// for `source`'s run; `None` for a mesh whose faces share vertices.
    pub fn soup_warning(&self, source: &str) -> Option<String> {
        self.shares_no_vertex().then(|| {
            format!(
                "{source}: no two of its {} faces share a vertex (a triangle soup, as STL \
                 exports give), so curvature and the line families find nothing; weld it \
                 (--weld, or weld = true in a scene) to join the faces at identical positions",
                self.n_faces()
            )
        })
    }

    /// For each vertex, whether some face uses it.
    pub fn referenced(&self) -> Vec<bool> {
        referenced(self.n_vertices(), &self.faces)
    }

    /// Axis-aligned bounding box (min, max).
    pub fn bounds(&self) -> ([f64; 3], [f64; 3]) {
        let mut lo = [f64::INFINITY; 3];
        let mut hi = [f64::NEG_INFINITY; 3];
        for p in &self.positions {
            for k in 0..3 {
                lo[k] = lo[k].min(p[k]);
                hi[k] = hi[k].max(p[k]);
            }
        }
        (lo, hi)
    }

    /// Returns a copy with every position transformed by `f`. Stored
    /// normals are dropped: `f` need not be a rotation.
    pub fn map_positions(&self, mut f: impl FnMut([f64; 3]) -> [f64; 3]) -> Mesh {
        Mesh {
            positions: self.positions.iter().map(|&p| f(p)).collect(),
            faces: self.faces.clone(),
            normals: None,
        }
    }
}

/// For each of `nv` vertices, whether one of `faces` uses it.
pub fn referenced(nv: usize, faces: &[[u32; 3]]) -> Vec<bool> {
    let mut r = vec![false; nv];
    for f in faces {
        for &v in f {
            r[v as usize] = true;
        }
    }
    r
}

/// Rejects face lists no stage can work with: none at all, more elements than
/// 32-bit indices address, or an index past the `nv` vertices. `source` names
/// where the data came from in the error.
pub fn check_faces(nv: usize, faces: &[[u32; 3]], source: &str) -> Result<()> {
    if faces.is_empty() {
        return Err(Error::input(source, "faces", "the mesh has no faces"));
    }
    if nv >= u32::MAX as usize || faces.len() >= (u32::MAX / 3) as usize {
        return Err(Error::input(
            source,
            "mesh",
            format!(
                "{nv} vertices / {} faces exceed the 32-bit index range",
                faces.len()
            ),
        ));
    }
    for (i, f) in faces.iter().enumerate() {
        if let Some(&bad) = f.iter().find(|&&v| v as usize >= nv) {
            return Err(Error::input(
                source,
                format!("face {i}"),
                format!("vertex index {bad} out of range (the mesh has {nv} vertices)"),
            ));
        }
    }
    Ok(())
}

/// Rejects a non-finite coordinate, naming the vertex.
pub fn check_positions(positions: &[[f64; 3]], source: &str) -> Result<()> {
    for (i, p) in positions.iter().enumerate() {
        if !p.iter().all(|c| c.is_finite()) {
            return Err(Error::input(
                source,
                format!("vertex {i}"),
                format!("non-finite coordinate ({}, {}, {})", p[0], p[1], p[2]),
            ));
        }
    }
    Ok(())
}

/// A characteristic feature size of a mesh: the median edge length (over
/// each face's three edges, so interior edges count twice, like trimesh2's
/// `TriMesh::feature_size`, which approximates the same median by sampling).
/// Feature-line thresholds are scaled by it, so they do not depend on the
/// mesh's units. Non-finite lengths are ignored; 0 for a mesh without faces.
pub fn feature_size(positions: &[[f64; 3]], faces: &[[u32; 3]]) -> f64 {
    let mut l: Vec<f64> = faces
        .iter()
        .flat_map(|f| {
            (0..3).map(move |k| {
                let (a, b) = (positions[f[k] as usize], positions[f[(k + 1) % 3] as usize]);
                ((a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2) + (a[2] - b[2]).powi(2)).sqrt()
            })
        })
        .filter(|x| x.is_finite())
        .collect();
    if l.is_empty() {
        return 0.0;
    }
    let mid = l.len() / 2;
    let (_, m, _) = l.select_nth_unstable_by(mid, f64::total_cmp);
    *m
}
