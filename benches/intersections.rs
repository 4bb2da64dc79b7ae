//! Intersection benches (`kernels/intersections.cl` ↔
//! `src/stages/intersections.rs`, twin `src/cpu/intersections.rs`): what
//! Line Art's intersection lines cost per pose.
//!
//! Input: two unit icospheres of level 5 (20,480 faces each) crossing, at
//! the origin and (turned) at (1, 0, 0), as one mesh with a group per
//! sphere (their curve is the circle x = 0.5 of radius √0.75). Groups:
//! - `intersections/find/<input>`: the device search over a built tree
//!   (`isect_find`, counters and read-back, the sort), host wall time;
//!   `intersections/find-kernel/<input>` its kernel time alone;
//! - `intersections/pose/<input>`: a new pose from scratch on the device
//!   (`Bvh::refit` of the positions, then the search);
//! - `intersections/twin/<input>`: the CPU twin's search over its tree;
//! - `intersections/reference/<input>`: the f64 brute force over every
//!   pair of faces of different groups (an exact box test first).
//!
//! A warm-up call before the groups pays for JIT compilation.
//! `SHAPECUE_DEVICE` picks the device as for the CLI.

mod common;

use criterion::{Criterion, criterion_group, criterion_main};
use shapecue::cpu::bvh::Tree;
use shapecue::cpu::intersections as twin;
use shapecue::mesh::{Mesh, icosphere};
use shapecue::spec::intersections::IntersectionOptions;
use shapecue::stages::bvh::Bvh;
use shapecue::stages::intersections::Intersections;
use std::hint::black_box;
use std::time::Duration;

/// Two crossing icospheres of `level` as one mesh, and each one's faces.
fn spheres(level: u32) -> (Mesh, Vec<usize>) {
    let a = icosphere(1.0, level);
    // turned, so that the two tessellations are not mirror images
    let b = icosphere(1.0, level).map_positions(|p| {
        let (s, c) = 0.7f64.sin_cos();
        let (s2, c2) = 1.1f64.sin_cos();
        let q = [c * p[0] + s * p[2], p[1], -s * p[0] + c * p[2]];
        [c2 * q[0] - s2 * q[1] + 1.0, s2 * q[0] + c2 * q[1], q[2]]
    });
    let base = a.positions.len() as u32;
    let counts = vec![a.faces.len(), b.faces.len()];
    let mut m = a;
    m.positions.extend(&b.positions);
    m.faces.extend(b.faces.iter().map(|f| f.map(|v| v + base)));
    (m, counts)
}

fn bench(c: &mut Criterion) {
    let Some(gpu) = common::gpu("intersections") else {
        return;
    };
    let (m, counts) = spheres(5);
    let name = "spheres20k";
    let pos: Vec<[f32; 3]> = (m.positions.iter()).map(|p| p.map(|x| x as f32)).collect();
    let opts = IntersectionOptions::by_input(&counts);
    let mut bvh = Bvh::new(gpu.clone(), pos.len(), &m.faces).expect("bvh");
    bvh.build(&pos).expect("build");
    let mut dev = Intersections::new(gpu, m.faces.len(), &opts).expect("intersections");
    let (segs, stats) = dev.find(&bvh).expect("warm-up");
    eprintln!(
        "intersections bench: {name}: {} faces, {} pairs tested, {} segments",
        m.faces.len(),
        stats.pairs_tested,
        segs.len()
    );
    let tree = Tree::new("spheres", &pos, &m.faces).expect("twin tree");
    let mut g = c.benchmark_group("intersections");
    g.sample_size(10)
        .warm_up_time(Duration::from_secs(1))
        .measurement_time(Duration::from_secs(4));
    g.bench_function(format!("find/{name}"), |b| {
        b.iter(|| dev.find(black_box(&bvh)).expect("find"))
    });
    g.bench_function(format!("find-kernel/{name}"), |b| {
        b.iter_custom(|iters| {
            let mut ms = 0.0;
            for _ in 0..iters {
                dev.find(&bvh).expect("find");
                ms += dev.timing().kernel_ms;
            }
            Duration::from_secs_f64(ms * 1e-3)
        })
    });
    g.bench_function(format!("pose/{name}"), |b| {
        b.iter(|| {
            bvh.refit(black_box(&pos)).expect("refit");
            dev.find(&bvh).expect("find")
        })
    });
    g.bench_function(format!("twin/{name}"), |b| {
        b.iter(|| twin::find(&tree, black_box(&pos), &m.faces, &opts).expect("twin"))
    });
    let p64: Vec<[f64; 3]> = pos.iter().map(|p| p.map(f64::from)).collect();
    g.bench_function(format!("reference/{name}"), |b| {
        b.iter(|| twin::find_brute(black_box(&p64), &m.faces, &opts).expect("reference"))
    });
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
