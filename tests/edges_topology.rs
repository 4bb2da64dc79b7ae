//! The edge and cap buffers built once per topology (`mesh::edges`): entry
//! for entry against the hash-map build they replaced, bad faces, and the
//! build time on large meshes (ignored by default).

mod common;

use common::shared_mesh;

use shapecue::mesh::edges::EdgeTopology;
use shapecue::mesh::{self, Mesh};

/// The edge and cap buffers as the first implementation built them (a hash
/// map from vertex pairs to face lists, filled in face order; cap pairs
/// from the incident entries of each vertex): the oracle that the
/// linear-time build in `src/mesh/edges.rs` must reproduce entry for entry.
fn hashmap_topology(mesh: &Mesh, marked: &[[u32; 2]], with_caps: bool) -> EdgeTopology {
    use std::collections::HashMap;
    let nv = mesh.n_vertices();
    let mut around: HashMap<(u32, u32), Vec<[u32; 3]>> =
        HashMap::with_capacity(mesh.n_faces() * 3 / 2 + 1);
    let mut order: Vec<(u32, u32)> = Vec::with_capacity(mesh.n_faces() * 3 / 2 + 1);
    for f in &mesh.faces {
        for k in 0..3 {
            let (a, b, c) = (f[k], f[(k + 1) % 3], f[(k + 2) % 3]);
            if a == b {
                continue;
            }
            let key = (a.min(b), a.max(b));
            around
                .entry(key)
                .or_insert_with(|| {
                    order.push(key);
                    Vec::new()
                })
                .push([a, b, c]);
        }
    }
    let mut edges = Vec::new();
    let mut entry_of: HashMap<(u32, u32), Vec<u32>> = HashMap::new();
    let (mut boundary, mut non_manifold) = (0, 0);
    for key in &order {
        let list = &around[key];
        boundary += (list.len() == 1) as usize;
        non_manifold += (list.len() > 2) as usize;
        for pair in list.chunks(2) {
            let [a, b, c] = pair[0];
            let d = if pair.len() == 2 { pair[1][2] } else { a };
            entry_of.entry(*key).or_default().push(edges.len() as u32);
            edges.push([a, b, c, d]);
        }
    }
    let mut n_marked = 0;
    for &[a, b] in marked {
        for &e in &entry_of[&(a.min(b), a.max(b))] {
            let e = &mut edges[e as usize];
            if e[3] != e[0] {
                e[3] = e[0];
                n_marked += 1;
            }
        }
    }
    let mut caps = Vec::new();
    if with_caps {
        // CSR of incident edge entries per vertex.
        let mut off = vec![0u32; nv + 1];
        for e in &edges {
            off[e[0] as usize + 1] += 1;
            off[e[1] as usize + 1] += 1;
        }
        for v in 0..nv {
            off[v + 1] += off[v];
        }
        let mut fill = off.clone();
        let mut inc = vec![0u32; off[nv] as usize];
        for (i, e) in edges.iter().enumerate() {
            for v in [e[0], e[1]] {
                inc[fill[v as usize] as usize] = i as u32;
                fill[v as usize] += 1;
            }
        }
        let key = |e: [u32; 4]| (e[0].min(e[1]), e[0].max(e[1]));
        for v in 0..nv {
            let list = &inc[off[v] as usize..off[v + 1] as usize];
            for (j, &a) in list.iter().enumerate() {
                for &b in &list[j + 1..] {
                    if key(edges[a as usize]) != key(edges[b as usize]) {
                        caps.push([a.min(b), a.max(b)]);
                    }
                }
            }
        }
    }
    EdgeTopology {
        edges,
        caps,
        boundary,
        non_manifold,
        marked: n_marked,
    }
}

/// A soup over few vertices: many non-manifold edges, collapsed faces
/// (two equal corners) and both orientations of shared edges.
fn random_soup(nv: u32, nf: usize, seed: u64) -> Mesh {
    let mut s = seed;
    let mut idx = || (mesh::splitmix(&mut s) * nv as f64) as u32 % nv;
    let positions = (0..nv)
        .map(|i| [i as f64, (i * i % 7) as f64, (i % 3) as f64])
        .collect();
    let faces = (0..nf)
        .map(|_| {
            let a = idx();
            let b = idx();
            // One face in eight collapsed on purpose.
            let c = if a % 8 == 0 { a } else { idx() };
            [a, b, c]
        })
        .collect();
    Mesh {
        positions,
        faces,
        normals: None,
    }
}

#[test]
fn topology_matches_the_hashmap_build_entry_for_entry() {
    let mut meshes: Vec<(String, Mesh)> = vec![
        ("cube".into(), mesh::cube(1.0)),
        ("cylinder".into(), mesh::capped_cylinder(0.5, 1.0, 17)),
        ("cone".into(), mesh::cone(0.5, 1.0, 9)),
        ("icosphere".into(), mesh::icosphere(1.0, 3)),
        ("torus".into(), mesh::torus(1.0, 0.4, 40, 23)),
        ("plane".into(), mesh::plane(9, 1.0)),
    ];
    for seed in 0..6 {
        meshes.push((
            format!("soup {seed}"),
            random_soup(12 + 7 * seed as u32, 300, seed),
        ));
    }
    if let Some(m) = shared_mesh("stanford-bunny.obj") {
        meshes.push(("bunny".into(), m));
    }
    for (name, m) in &meshes {
        // Mark a few edges of the mesh (the first side of every 5th face).
        let marked: Vec<[u32; 2]> = m
            .faces
            .iter()
            .step_by(5)
            .filter(|f| f[0] != f[1])
            .map(|f| [f[0], f[1]])
            .take(20)
            .collect();
        for marks in [&[][..], &marked[..]] {
            let want = hashmap_topology(m, marks, true);
            let got = EdgeTopology::new(m, marks, name).unwrap();
            assert_eq!(got, want, "{name}, {} marked", marks.len());
            let mut want = want;
            want.caps.clear();
            let got = EdgeTopology::without_caps(m, marks, name).unwrap();
            assert_eq!(got, want, "{name} without caps, {} marked", marks.len());
        }
    }
}

#[test]
fn a_face_past_the_vertices_is_a_clear_error() {
    let m = Mesh {
        positions: vec![[0.0; 3]; 3],
        faces: vec![[0, 1, 2], [0, 2, 7]],
        normals: None,
    };
    let e = EdgeTopology::without_caps(&m, &[], "bad.obj").unwrap_err();
    let msg = e.to_string();
    assert!(
        msg.contains("bad.obj") && msg.contains("face 1") && msg.contains('7'),
        "{msg}"
    );
}

/// Topology build times, old (hash map) and new, in one process so that both
/// see the same machine: `cargo test --release --test edges -- --ignored
/// --nocapture topology_times`. CPU time of this thread (Linux
/// `/proc/thread-self/schedstat`, wall time elsewhere), so that other
/// processes on a shared machine inflate it less; minimum of 5 runs (1 for
/// the hash map on the 2M-vertex torus, which takes seconds).
#[test]
#[ignore = "timing, run by hand"]
fn topology_times() {
    fn cpu_ns() -> Option<u64> {
        let s = std::fs::read_to_string("/proc/thread-self/schedstat").ok()?;
        s.split_whitespace().next()?.parse().ok()
    }
    let mut meshes: Vec<(String, Mesh)> = Vec::new();
    if let Some(m) = shared_mesh("stanford-bunny.obj") {
        meshes.push(("bunny".into(), m));
    }
    let (nu, nv) = mesh::torus_resolution_for(2_000_000);
    meshes.push(("torus 2M".into(), mesh::torus(1.0, 0.4, nu, nv)));
    let min_ms = |runs: usize, f: &mut dyn FnMut()| {
        (0..runs)
            .map(|_| {
                let (t, c) = (std::time::Instant::now(), cpu_ns());
                f();
                match (c, cpu_ns()) {
                    (Some(a), Some(b)) => (b - a) as f64 * 1e-6,
                    _ => t.elapsed().as_secs_f64() * 1e3,
                }
            })
            .fold(f64::INFINITY, f64::min)
    };
    for (name, m) in &meshes {
        let n_old = if m.n_vertices() > 100_000 { 1 } else { 5 };
        let new_edges = min_ms(5, &mut || {
            drop(std::hint::black_box(EdgeTopology::without_caps(
                m,
                &[],
                name,
            )))
        });
        let new_all = min_ms(5, &mut || {
            drop(std::hint::black_box(EdgeTopology::new(m, &[], name)))
        });
        let old_edges = min_ms(n_old, &mut || {
            drop(std::hint::black_box(hashmap_topology(m, &[], false)))
        });
        let old_all = min_ms(n_old, &mut || {
            drop(std::hint::black_box(hashmap_topology(m, &[], true)))
        });
        println!(
            "{name} ({} vertices): edge buffer {old_edges:.1} -> {new_edges:.1} ms, \
             with cap pairs {old_all:.1} -> {new_all:.1} ms (CPU time)",
            m.n_vertices()
        );
    }
}
