//! Edge topology for the edges stage (House & Li), built once per
//! mesh topology: the edge buffer, the adjacency cap buffer, marked edges and
//! per-vertex normals for McGuire-Hughes caps.
//!
//! Edge buffer: one `[i0, i1, i2, i3]` per unique undirected edge. `i0 → i1`
//! is the edge as the *first* face using it traverses it (faces in file
//! order), `i2` is that face's third vertex, `i3` the third vertex of the
//! second face. Boundary edges (one face) and marked edges have `i3 == i0`,
//! House & Li's "boundary and marked" test.
//!
//! **Non-manifold edges** (3 or more faces): the faces around the edge are
//! taken in file order and paired, (f0, f1), (f2, f3), ...; the edge is emitted
//! once per pair, with `i0 → i1` from the first face of the pair. An odd face
//! left over gives one more entry as a boundary edge (`i3 == i0`), so an edge
//! with three faces is drawn (boundary rule) and one with four is tested like
//! two ordinary edges. [`EdgeTopology::non_manifold`] counts such edges.
//!
//! **Cap buffer**: every unordered pair `(e0, e1)`, `e0 < e1`, of edge-buffer
//! entries that share an end vertex (`Σ_v deg(v)(deg(v) − 1)/2` pairs), in
//! order of the shared vertex. Pairs between entries of the same undirected
//! edge (non-manifold duplicates) are left out: they share both ends.

use std::collections::HashMap;
use std::path::Path;

use super::Mesh;
use crate::error::{Error, Result};

/// The index buffers of the edges stage, built by [`EdgeTopology::new`].
#[derive(Clone, Debug, Default, PartialEq)]
pub struct EdgeTopology {
    /// `[i0, i1, i2, i3]` per edge entry (see the module documentation).
    pub edges: Vec<[u32; 4]>,
    /// `[e0, e1]` per pair of edge entries sharing an end vertex.
    pub caps: Vec<[u32; 2]>,
    /// Edges used by exactly one face.
    pub boundary: usize,
    /// Undirected edges used by three or more faces.
    pub non_manifold: usize,
    /// Edge entries forced drawable by a marked-edge list.
    pub marked: usize,
}

impl EdgeTopology {
    /// Builds the edge and cap buffers of `mesh`; `marked` lists vertex-index
    /// pairs to draw always (each must be an edge of the mesh; see
    /// [`read_marked`]). `source` names the marked list (or the mesh) in errors.
    ///
    /// # Errors
    /// [`Error::InvalidInput`] for a marked pair that is not an edge, an
    /// index past the vertices, or more cap pairs than [`MAX_CAP_PAIRS`].
    pub fn new(mesh: &Mesh, marked: &[[u32; 2]], source: &str) -> Result<EdgeTopology> {
        Self::build(mesh, marked, source, true)
    }

    /// As [`EdgeTopology::new`] without the cap buffer (`caps` empty), for the
    /// variants that need none (no caps, McGuire-Hughes caps): no limit on
    /// vertex degree, less memory and time.
    pub fn without_caps(mesh: &Mesh, marked: &[[u32; 2]], source: &str) -> Result<EdgeTopology> {
        Self::build(mesh, marked, source, false)
    }

    /// Adds the cap buffer to a topology built [`without_caps`](Self::without_caps)
    /// (`nv`: the mesh's vertex count), as [`EdgeTopology::new`] would have
    /// built it; a no-op when the caps are already there.
    ///
    /// # Errors
    /// [`Error::InvalidInput`] for more cap pairs than [`MAX_CAP_PAIRS`].
    pub fn add_caps(&mut self, nv: usize, source: &str) -> Result<()> {
        if self.caps.is_empty() {
            let (off, inc) = incidences(nv, &self.edges);
            check_cap_count(&off, source)?;
            self.caps = pairs_of(&off, &inc);
        }
        Ok(())
    }

    /// Builds the edge buffer (with marked edges) and, `with_caps`, the cap
    /// buffer.
    fn build(
        mesh: &Mesh,
        marked: &[[u32; 2]],
        source: &str,
        with_caps: bool,
    ) -> Result<EdgeTopology> {
        let nv = mesh.n_vertices();
        let sides = sides_by_edge(nv, &mesh.faces, source)?;
        let Entries {
            mut edges,
            entry_of,
            boundary,
            non_manifold,
        } = edge_entries(&mesh.faces, sides);
        let n_marked = mark_edges(&mut edges, &entry_of, marked, nv, source)?;
        let mut t = EdgeTopology {
            edges,
            caps: Vec::new(),
            boundary,
            non_manifold,
            marked: n_marked,
        };
        if with_caps {
            t.add_caps(nv, source)?;
        }
        Ok(t)
    }
}

/// The edge buffer with what the marked edges and the counts need.
struct Entries {
    edges: Vec<[u32; 4]>,
    /// The entries of each non-manifold edge (by its sorted ends).
    entry_of: HashMap<(u32, u32), Vec<u32>>,
    boundary: usize,
    non_manifold: usize,
}

/// Builds the edge entries from the face sides grouped by
/// [`sides_by_edge`] (`next`, `head`), which are freed on return.
fn edge_entries(faces: &[[u32; 3]], (next, head): (Vec<u32>, Vec<bool>)) -> Entries {
    // Edges in order of their first face side (the order a hash map
    // filled in face order would give), each with its faces in file order.
    let mut edges = Vec::with_capacity(faces.len() * 3 / 2 + 1);
    let mut entry_of: HashMap<(u32, u32), Vec<u32>> = HashMap::new();
    let (mut boundary, mut non_manifold) = (0, 0);
    let mut list: Vec<[u32; 3]> = Vec::new();
    for (h0, _) in head.iter().enumerate().filter(|(_, is)| **is) {
        list.clear();
        let mut h = h0 as u32;
        while h != NONE {
            let (f, k) = (&faces[h as usize / 3], h as usize % 3);
            list.push([f[k], f[(k + 1) % 3], f[(k + 2) % 3]]);
            h = next[h as usize];
        }
        let key = (list[0][0].min(list[0][1]), list[0][0].max(list[0][1]));
        if list.len() == 1 {
            boundary += 1;
        }
        if list.len() > 2 {
            non_manifold += 1;
        }
        for pair in list.chunks(2) {
            let [a, b, c] = pair[0];
            let d = if pair.len() == 2 { pair[1][2] } else { a };
            if list.len() > 2 {
                entry_of.entry(key).or_default().push(edges.len() as u32);
            }
            edges.push([a, b, c, d]);
        }
    }
    Entries {
        edges,
        entry_of,
        boundary,
        non_manifold,
    }
}

/// Marks the `marked` edges, i3 = i0 on every entry of each; the number of
/// entries that were not marked already.
fn mark_edges(
    edges: &mut [[u32; 4]],
    entry_of: &HashMap<(u32, u32), Vec<u32>>,
    marked: &[[u32; 2]],
    nv: usize,
    source: &str,
) -> Result<usize> {
    let mut n_marked = 0;
    if marked.is_empty() {
        return Ok(n_marked);
    }
    let key = |a: u32, b: u32| (a.min(b), a.max(b));
    // Only the marked pairs are looked up: one scan of the edges finds
    // the first entry of each.
    let mut index: HashMap<(u32, u32), u32> =
        marked.iter().map(|&[a, b]| (key(a, b), NONE)).collect();
    for (i, e) in edges.iter().enumerate() {
        if let Some(first) = index.get_mut(&key(e[0], e[1]))
            && *first == NONE
        {
            *first = i as u32;
        }
    }
    for (line, &[a, b]) in marked.iter().enumerate() {
        let el = format!("marked edge {} ({a}, {b})", line + 1);
        if a as usize >= nv || b as usize >= nv {
            return Err(Error::input(
                source,
                el,
                format!("vertex index past the mesh's {nv} vertices"),
            ));
        }
        let k = key(a, b);
        let first = index[&k];
        if first == NONE {
            return Err(Error::input(source, el, "not an edge of the mesh"));
        }
        let entries = entry_of.get(&k).cloned().unwrap_or_else(|| vec![first]);
        for e in entries {
            let e = &mut edges[e as usize];
            if e[3] != e[0] {
                e[3] = e[0];
                n_marked += 1;
            }
        }
    }
    Ok(n_marked)
}

/// End of a list in [`sides_by_edge`].
const NONE: u32 = u32::MAX;

/// Groups the face sides (side `3f + k` runs from corner k of face f to
/// corner k + 1; collapsed sides, with equal ends, are left out) by
/// undirected edge in linear time, without hashing: the sides are bucketed
/// by their lower vertex (a counting sort, which keeps side order), and
/// within a bucket the sides with the same upper vertex are linked in side
/// order. Returns `next` (the next side of the same edge, or [`NONE`]) and
/// `head` (the side is its edge's first). A hash map from vertex pairs to
/// face lists gives the same groups with one allocation per edge, and is
/// much slower (docs/performance.md).
fn sides_by_edge(nv: usize, faces: &[[u32; 3]], source: &str) -> Result<(Vec<u32>, Vec<bool>)> {
    let m = faces.len() * 3;
    if m >= NONE as usize {
        return Err(Error::input(
            source,
            "faces",
            format!(
                "{} faces exceed the 32-bit face-side index range",
                faces.len()
            ),
        ));
    }
    let mut off = vec![0u32; nv + 1];
    for (fi, f) in faces.iter().enumerate() {
        if let Some(&v) = f.iter().find(|&&v| v as usize >= nv) {
            return Err(Error::input(
                source,
                format!("face {fi}"),
                format!("vertex index {v} past the mesh's {nv} vertices"),
            ));
        }
        for k in 0..3 {
            let (a, b) = (f[k], f[(k + 1) % 3]);
            if a != b {
                off[a.min(b) as usize + 1] += 1;
            }
        }
    }
    for v in 0..nv {
        off[v + 1] += off[v];
    }
    let mut fill = off.clone();
    // (side, upper vertex) per side, bucketed by lower vertex.
    let mut bucket = vec![[0u32; 2]; off[nv] as usize];
    for (fi, f) in faces.iter().enumerate() {
        for k in 0..3 {
            let (a, b) = (f[k], f[(k + 1) % 3]);
            if a != b {
                let slot = &mut fill[a.min(b) as usize];
                bucket[*slot as usize] = [(3 * fi + k) as u32, a.max(b)];
                *slot += 1;
            }
        }
    }
    drop(fill);
    let mut next = vec![NONE; m];
    let mut head = vec![false; m];
    // Per upper vertex: the bucket that last saw it and its last side there.
    let mut seen_in = vec![NONE; nv];
    let mut last = vec![0u32; nv];
    for v in 0..nv {
        for &[h, hi] in &bucket[off[v] as usize..off[v + 1] as usize] {
            let hi = hi as usize;
            if seen_in[hi] != v as u32 {
                seen_in[hi] = v as u32;
                head[h as usize] = true;
            } else {
                next[last[hi] as usize] = h;
            }
            last[hi] = h;
        }
    }
    Ok((next, head))
}

/// Largest number of cap pairs: 16 floats per pair must stay addressable with
/// 32-bit indices on the device.
pub const MAX_CAP_PAIRS: u64 = (u32::MAX / 16) as u64;

/// Rejects meshes whose cap buffer would not fit ([`MAX_CAP_PAIRS`]): the
/// count grows with the square of vertex degrees (a fan of 100k triangles
/// around one apex has 5·10⁹ pairs), so it is counted from the incidence
/// offsets `off` before anything is allocated, and the error names the
/// vertex of highest degree.
fn check_cap_count(off: &[u32], source: &str) -> Result<()> {
    let deg = |v: usize| u64::from(off[v + 1] - off[v]);
    let nv = off.len() - 1;
    let total: u64 = (0..nv).map(|v| deg(v) * deg(v).saturating_sub(1) / 2).sum();
    if total > MAX_CAP_PAIRS {
        let (v, d) = (0..nv)
            .map(|v| (v, deg(v)))
            .max_by_key(|p| p.1)
            .unwrap_or((0, 0));
        return Err(Error::input(
            source,
            format!("vertex {v}"),
            format!(
                "{total} adjacency cap pairs (vertex {v} has {d} edges) exceed the limit of \
                 {MAX_CAP_PAIRS}; only --caps none or mh can draw this mesh"
            ),
        ));
    }
    Ok(())
}

/// The edge entries at each vertex (CSR: offsets of length V+1), each as
/// (entry, other end), in entry order.
fn incidences(nv: usize, edges: &[[u32; 4]]) -> (Vec<u32>, Vec<[u32; 2]>) {
    let mut off = vec![0u32; nv + 1];
    for e in edges {
        off[e[0] as usize + 1] += 1;
        off[e[1] as usize + 1] += 1;
    }
    for v in 0..nv {
        off[v + 1] += off[v];
    }
    let mut fill = off.clone();
    let mut inc = vec![[0u32; 2]; off[nv] as usize];
    for (i, e) in edges.iter().enumerate() {
        for (v, other) in [(e[0], e[1]), (e[1], e[0])] {
            inc[fill[v as usize] as usize] = [i as u32, other];
            fill[v as usize] += 1;
        }
    }
    (off, inc)
}

/// Every pair of edge entries sharing an end vertex (see the module documentation).
pub fn cap_pairs(nv: usize, edges: &[[u32; 4]]) -> Vec<[u32; 2]> {
    let (off, inc) = incidences(nv, edges);
    pairs_of(&off, &inc)
}

fn pairs_of(off: &[u32], inc: &[[u32; 2]]) -> Vec<[u32; 2]> {
    let nv = off.len() - 1;
    let n_pairs: usize = (0..nv)
        .map(|v| {
            let d = (off[v + 1] - off[v]) as usize;
            d * d.saturating_sub(1) / 2
        })
        .sum();
    let mut caps = Vec::with_capacity(n_pairs);
    for v in 0..nv {
        let list = &inc[off[v] as usize..off[v + 1] as usize];
        for (j, &[a, oa]) in list.iter().enumerate() {
            for &[b, ob] in &list[j + 1..] {
                // Both entries end at v: they are the same undirected edge
                // (non-manifold duplicates) exactly when their other ends agree.
                if oa != ob {
                    caps.push([a.min(b), a.max(b)]);
                }
            }
        }
    }
    caps
}

/// Parses a marked-edge list: one pair of 0-based vertex indices per line,
/// separated by whitespace or a comma; blank lines and `#` comments are
/// skipped. `source` names the text in errors, which give the line number.
pub fn parse_marked(text: &str, source: &str) -> Result<Vec<[u32; 2]>> {
    let mut out = Vec::new();
    for (i, raw) in text.lines().enumerate() {
        let line = raw.split('#').next().unwrap_or("").trim();
        if line.is_empty() {
            continue;
        }
        let el = format!("line {}", i + 1);
        let parts: Vec<&str> = line
            .split(|c: char| c == ',' || c.is_whitespace())
            .filter(|s| !s.is_empty())
            .collect();
        if parts.len() != 2 {
            return Err(Error::input(
                source,
                el,
                format!(
                    "expected two vertex indices, found {} fields in {line:?}",
                    parts.len()
                ),
            ));
        }
        let mut pair = [0u32; 2];
        for (k, p) in parts.iter().enumerate() {
            pair[k] = p.parse::<u32>().map_err(|_| {
                Error::input(
                    source,
                    el.clone(),
                    format!("{p:?} is not a vertex index (0-based, non-negative)"),
                )
            })?;
        }
        if pair[0] == pair[1] {
            return Err(Error::input(
                source,
                el,
                format!("edge ({}, {}) joins a vertex to itself", pair[0], pair[1]),
            ));
        }
        out.push(pair);
    }
    Ok(out)
}

/// Reads and parses a marked-edge file (see [`parse_marked`]).
pub fn read_marked(path: &Path) -> Result<Vec<[u32; 2]>> {
    let text = std::fs::read_to_string(path).map_err(|source| Error::Io {
        path: path.to_path_buf(),
        source,
    })?;
    parse_marked(&text, &path.display().to_string())
}
