//! BVH benches (`kernels/bvh.cl` ↔ `src/stages/bvh.rs`, twin
//! `src/cpu/bvh.rs`): what a line drawing's exact visibility will pay per
//! topology, per pose and per view.
//!
//! Groups, on generated tori of 20k and 200k vertices (quick mode: 20k):
//! - `bvh/build/<mesh>`: the first pose (Morton codes, the project's radix
//!   sort, Karras's hierarchy, refit), host wall time; `bvh/build-twin/<mesh>`
//!   the CPU twin's;
//! - `bvh/refit/<mesh>`: a new pose on the same tree (upload and refit);
//!   `bvh/refit-twin/<mesh>`;
//! - `bvh/occluded/<mesh>`: 100k segments from surface points towards an
//!   eye at three bounding radii (upload, traversal, read-back);
//!   `bvh/occluded-twin/<mesh>` the twin on 10k of them (per query cost
//!   is what compares).
//!
//! A warm-up call before each group pays for JIT compilation.
//! `SHAPECUE_DEVICE` picks the device as for the CLI.

mod common;

use criterion::{Criterion, criterion_group, criterion_main};
use shapecue::cpu::bvh::Tree;
use shapecue::mesh::{Generated, Mesh};
use shapecue::spec::bvh::{BvhQuery, NONE};
use shapecue::stages::bvh::Bvh;
use std::hint::black_box;
use std::time::Duration;

fn positions(m: &Mesh, twist: f64) -> Vec<[f32; 3]> {
    (m.positions.iter())
        .map(|p| {
            let (s, c) = (twist * p[2]).sin_cos();
            [
                (c * p[0] - s * p[1]) as f32,
                (s * p[0] + c * p[1]) as f32,
                p[2] as f32,
            ]
        })
        .collect()
}

/// Segments from each face's centroid (its face excluded) to an eye at
/// three bounding radii along (1, 1, 1), `n` of them, faces in turn.
fn queries(m: &Mesh, pos: &[[f32; 3]], n: usize) -> Vec<BvhQuery> {
    let eye = [3.0f32 * 1.4; 3];
    (0..n)
        .map(|i| {
            let f = i % m.n_faces();
            let c = m.faces[f].map(|v| pos[v as usize]);
            let o: [f32; 3] = std::array::from_fn(|k| (c[0][k] + c[1][k] + c[2][k]) / 3.0);
            BvhQuery {
                origin: [o[0], o[1], o[2], 0.0],
                target: [eye[0], eye[1], eye[2], 0.0],
                exclude: [f as u32, NONE, NONE, NONE],
            }
        })
        .collect()
}

fn bench(c: &mut Criterion) {
    let Some(gpu) = common::gpu("bvh") else {
        return;
    };
    let sizes: &[(&str, usize)] = if common::quick() {
        &[("torus20k", 20_000)]
    } else {
        &[("torus20k", 20_000), ("torus200k", 200_000)]
    };
    let mut g = c.benchmark_group("bvh");
    g.sample_size(10)
        .warm_up_time(Duration::from_secs(1))
        .measurement_time(Duration::from_secs(4));
    for &(name, n) in sizes {
        let (_, m) = Generated::Torus.mesh(n);
        let (p0, p1) = (positions(&m, 0.0), positions(&m, 0.5));
        let mut bvh = Bvh::new(gpu.clone(), m.n_vertices(), &m.faces).expect("bvh");
        bvh.build(&p0).expect("build");
        g.bench_function(format!("build/{name}"), |b| {
            b.iter(|| bvh.build(black_box(&p0)).expect("build"))
        });
        g.bench_function(format!("build-twin/{name}"), |b| {
            b.iter(|| Tree::new("torus", black_box(&p0), &m.faces).expect("twin"))
        });
        g.bench_function(format!("refit/{name}"), |b| {
            b.iter(|| bvh.refit(black_box(&p1)).expect("refit"))
        });
        let mut twin = Tree::new("torus", &p0, &m.faces).expect("twin");
        g.bench_function(format!("refit-twin/{name}"), |b| {
            b.iter(|| twin.refit(black_box(&p1), &m.faces))
        });
        let q = queries(&m, &p1, 100_000);
        g.bench_function(format!("occluded/{name}"), |b| {
            b.iter(|| bvh.occluded(black_box(&q)).expect("queries"))
        });
        g.bench_function(format!("occluded-twin/{name}"), |b| {
            b.iter(|| {
                (q[..10_000].iter())
                    .map(|x| twin.occluded(&p1, &m.faces, x))
                    .sum::<u32>()
            })
        });
    }
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
