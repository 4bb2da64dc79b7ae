//! The gather scheme's one-ring lists built on the device (as on GPUs) give
//! the same curvature, bit for bit, as the lists built on the host (as on CPU
//! devices): on a closed mesh, a mesh with a hole, a mesh with an unused
//! vertex, a vertex of very high valence and a single face, in f32 and f64,
//! on one and several face lanes. One test in its own binary: it switches
//! `SHAPECUE_RING_BUILD`, which every estimator made meanwhile reads.

mod common;

use common::gpu;
use shapecue::mesh::{self, Mesh};
use shapecue::spec::curvature::{Accumulate, CurvatureOptions, Precision};
use shapecue::stages::curvature::CurvatureEstimator;

fn run(
    m: &Mesh,
    o: CurvatureOptions,
    build: &str,
) -> (shapecue::spec::curvature::CurvatureField, String) {
    // SAFETY: the only test of this binary; nothing else reads the
    // environment concurrently.
    unsafe { std::env::set_var("SHAPECUE_RING_BUILD", build) };
    let mut est = CurvatureEstimator::new(gpu(), m.n_vertices(), &m.faces, o).unwrap();
    est.set_positions(&m.positions).unwrap();
    est.run().unwrap();
    (est.read().unwrap(), format!("{:?}", est.counts().unwrap()))
}

#[test]
fn device_built_one_rings_give_the_host_built_bits() {
    let mut holed = mesh::jittered_sphere(1.0, 3, 0.3, 5);
    holed.faces.truncate(holed.faces.len() - 7);
    let mut unused = mesh::icosphere(1.0, 2);
    unused.positions.push([5.0, 5.0, 5.0]);
    // a fan of 300 faces around one vertex (valence far above a mesh's)
    let mut fan = Mesh {
        positions: vec![[0.0, 0.0, 0.2]],
        faces: Vec::new(),
        normals: None,
    };
    for i in 0..300u32 {
        let a = i as f64 / 300.0 * std::f64::consts::TAU;
        fan.positions.push([a.cos(), a.sin(), 0.0]);
        fan.faces.push([0, 1 + i, 1 + (i + 1) % 300]);
    }
    let single = Mesh {
        positions: vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.3]],
        faces: vec![[0, 1, 2]],
        normals: None,
    };
    let meshes = [
        ("torus", mesh::torus(1.0, 0.4, 40, 24)),
        ("holed sphere", holed),
        ("unused vertex", unused),
        ("fan", fan),
        ("one face", single),
    ];
    for (what, m) in &meshes {
        for precision in [Precision::F32, Precision::F64] {
            if precision == Precision::F64 && !gpu().info.fp64 {
                continue;
            }
            for lanes in [1, 8] {
                let o = CurvatureOptions {
                    accumulate: Accumulate::Gather,
                    precision,
                    lanes: shapecue::spec::curvature::Lanes::Fixed(lanes),
                    ..CurvatureOptions::default()
                };
                let host = run(m, o, "host");
                let device = run(m, o, "device");
                assert!(host == device, "{what} {} {lanes} lanes", precision.name());
            }
        }
    }
}
