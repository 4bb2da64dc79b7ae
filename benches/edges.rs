//! Edges stage benches (`kernels/edges.cl` ↔ `src/stages/edges.rs`), House &
//! Li's comparison of the McGuire-Hughes and adjacency cap variants (House & Li).
//!
//! Groups, per caps variant (`none`, `mh`, `adjacency`) and mesh:
//! - `edges/<caps>/<mesh>`: `edges_detect` + the variant's cap kernel, from
//!   OpenCL profiling events, topology and positions already on the device,
//!   after a warm-up run that pays for JIT.
//! - `edges/<caps>/<mesh>/frame`: host wall time of a whole frame as
//!   `shapecue edges --runs` times it: parameter upload, kernels, the
//!   compacted read-back of what was drawn (`EdgeStage::read_drawn`), and
//!   the GL frame (the uploaded mesh, edges, caps, colour read-back) at
//!   1024x1024 with MSAA 4 and 2-pixel edges, the mesh fitted in view. The
//!   adjacency line prints the ratio to Blender's Line Art compute time on
//!   the same mesh (measured on this kind of 2-core machine, Blender 3.4.1).
//!   Without headless GL: kernels + read-back only (a message says so).
//! - `edges/readback/<mesh>`: the compacted read-back alone (adjacency caps).
//! - `edges/gl-mesh/<mesh>`: what llvmpipe itself costs for the image: the
//!   uploaded mesh drawn and the colour read back, no edges.
//! - `edges/topology/<mesh>`: the host topology, edge buffer and adjacency
//!   cap pairs (`EdgeTopology::new`), and `edges/topology-edges/<mesh>` the
//!   edge buffer alone (`EdgeTopology::without_caps`).
//!
//! Inputs: generated cube, capped cylinder, cone, icosphere (level 3), the
//! shared teapot, fandisk, Stanford bunny, armadillo and lucy (skipped with a
//! message when absent), and a generated torus of about 1M edges; all
//! unit-sized at the origin. `SHAPECUE_BENCH_QUICK=1` restricts the run to
//! the bunny. `SHAPECUE_DEVICE` picks the device as for the CLI.

mod common;

use criterion::{Criterion, SamplingMode, criterion_group, criterion_main};
use glam::Vec3;
use shapecue::Mesh;
use shapecue::mesh::{self, edges::EdgeTopology, topology::vertex_normals};
use shapecue::render::edges::draw_edges;
use shapecue::render::{MeshStyle, Placement, RenderOptions, Renderer, framed};
use shapecue::report::metrics::median;
use shapecue::spec::edges::{CapMode, EdgeParams};
use shapecue::stages::edges::EdgeStage;
use std::time::{Duration, Instant};

const SIZE: (u32, u32) = (1024, 1024);

/// Blender 3.4.1 Line Art compute time per frame (contour + 30° crease +
/// loose edges, default quality), ms, on this kind of 2-core machine.
fn line_art_ms(mesh: &str) -> Option<f64> {
    match mesh {
        "fandisk" => Some(6.9),
        "bunny" => Some(41.0),
        "armadillo" => Some(88.0),
        "lucy" => Some(118.0),
        _ => None,
    }
}

fn inputs() -> Vec<(&'static str, Mesh)> {
    let quick = common::quick();
    let mut v: Vec<(&'static str, Option<Mesh>)> = Vec::new();
    if !quick {
        v.push(("cube", Some(mesh::cube(1.0))));
        v.push(("cylinder", Some(mesh::capped_cylinder(0.5, 1.0, 32))));
        v.push(("cone", Some(mesh::cone(0.5, 1.0, 32))));
        v.push(("icosphere", Some(mesh::icosphere(0.5, 3))));
        v.push(("teapot", common::shared_mesh("edges", "teapot.obj")));
        v.push(("fandisk", common::shared_mesh("edges", "fandisk.obj")));
    }
    v.push(("bunny", common::shared_mesh("edges", "stanford-bunny.obj")));
    if !quick {
        v.push(("armadillo", common::shared_mesh("edges", "armadillo.obj")));
        v.push(("lucy", common::shared_mesh("edges", "lucy.ply")));
    }
    if !quick {
        // A torus has 3 edges per vertex: 333,334 vertices ≈ 1M edges.
        let (nu, nv) = mesh::torus_resolution_for(333_334);
        v.push(("torus_1m", Some(mesh::torus(1.0, 0.4, nu, nv))));
    }
    v.into_iter()
        .filter_map(|(n, m)| m.map(|m| (n, mesh::unit_sized(&m))))
        .collect()
}

fn edges_benches(c: &mut Criterion) {
    let Some(gpu) = common::gpu("edges") else {
        return;
    };
    let mut renderer = match Renderer::new(RenderOptions {
        width: SIZE.0,
        height: SIZE.1,
        ..Default::default()
    }) {
        Ok(r) => Some(r),
        Err(e) => {
            eprintln!("edges bench: {e}; frame times exclude GL");
            None
        }
    };
    let mut g = c.benchmark_group("edges");
    g.sample_size(10)
        .sampling_mode(SamplingMode::Flat)
        .warm_up_time(Duration::from_millis(500))
        .measurement_time(Duration::from_secs(3));
    for (name, m) in inputs() {
        g.bench_function(format!("topology/{name}"), |b| {
            b.iter(|| EdgeTopology::new(&m, &[], name).expect("topology"))
        });
        g.bench_function(format!("topology-edges/{name}"), |b| {
            b.iter(|| EdgeTopology::without_caps(&m, &[], name).expect("topology"))
        });
        let topo = EdgeTopology::new(&m, &[], name).expect("topology");
        let cam = framed(
            Placement::Fit(Vec3::ONE),
            None,
            None,
            40.0,
            false,
            m.bounds(),
            SIZE.0 as f32 / SIZE.1 as f32,
        )
        .expect("camera");
        let mut p = EdgeParams::new(cam.view(SIZE.0, SIZE.1));
        p.line_width = 2.0;
        let mut stage = EdgeStage::new(gpu.clone(), &m, &topo).expect("stage");
        let pos: Vec<[f32; 3]> = m.positions.iter().map(|q| q.map(|c| c as f32)).collect();
        let nrm = vertex_normals(&m);
        if let Some(r) = renderer.as_mut() {
            r.upload_topology(&m.faces).expect("faces");
            r.upload_pose(&pos, &nrm, &[]).expect("pose");
        }
        eprintln!(
            "edges bench: {name}: {} vertices, {} edges, {} cap pairs",
            m.n_vertices(),
            topo.edges.len(),
            topo.caps.len()
        );
        for mode in CapMode::ALL {
            stage.run(&p, mode).expect("warm-up run"); // JIT
            g.bench_function(format!("{}/{name}", mode.name()), |b| {
                b.iter_custom(|iters| {
                    let mut ms = 0.0;
                    for _ in 0..iters {
                        ms += stage.run(&p, mode).expect("run").kernel_ms;
                    }
                    Duration::from_secs_f64(ms * 1e-3)
                })
            });
            let mut frames = Vec::new();
            g.bench_function(format!("{}/{name}/frame", mode.name()), |b| {
                b.iter_custom(|iters| {
                    let t = Instant::now();
                    for _ in 0..iters {
                        let t1 = Instant::now();
                        stage.run(&p, mode).expect("run");
                        let out = stage.read_drawn().expect("read");
                        if let Some(r) = renderer.as_mut() {
                            r.begin(&cam).expect("begin");
                            r.draw_uploaded(MeshStyle::default()).expect("mesh");
                            draw_edges(r, &out, [0.0, 0.0, 0.0, 1.0]).expect("edges");
                            std::hint::black_box(r.finish_color().expect("finish"));
                        }
                        frames.push(t1.elapsed().as_secs_f64() * 1e3);
                    }
                    t.elapsed()
                })
            });
            if let (CapMode::Adjacency, Some(la)) = (mode, line_art_ms(name)) {
                let f = median(&mut frames);
                eprintln!(
                    "edges/adjacency/{name}/frame: median {f:.1} ms = {:.2}× Line Art's {la} ms",
                    f / la
                );
            }
        }
        g.bench_function(format!("readback/{name}"), |b| {
            stage.run(&p, CapMode::Adjacency).expect("run");
            b.iter(|| stage.read_drawn().expect("read"))
        });
        if let Some(r) = renderer.as_mut() {
            g.bench_function(format!("gl-mesh/{name}"), |b| {
                b.iter(|| {
                    r.begin(&cam).expect("begin");
                    r.draw_uploaded(MeshStyle::default()).expect("mesh");
                    r.finish_color().expect("finish")
                })
            });
        }
    }
    g.finish();
}

criterion_group!(benches, edges_benches);
criterion_main!(benches);
