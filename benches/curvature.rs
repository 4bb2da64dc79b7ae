//! Curvature stage benches (`kernels/curvature*.cl` ↔ `src/stages/curvature/`).
//!
//! Groups:
//! - `curvature/<variant>/<input>`: kernel time from OpenCL profiling events
//!   (the sum of the pass times of one [`CurvatureEstimator::run`]), mesh
//!   already on the device, after one warm-up run that pays for JIT; the
//!   median is also printed with its ratio to trimesh2's single-threaded
//!   time on the same mesh.
//! - `curvature/<variant>-wall/<input>`: host wall time of one run (first
//!   enqueue to end of the last kernel), default variant only.
//! - `curvature/cpu-reference/bunny`: wall time of the f64 CPU reference,
//!   for scale.
//!
//! Inputs: the Stanford bunny and lucy from `shared/data/meshes` (skipped if absent)
//! and generated tori of about 500k and 2M vertices, each in the memory order
//! `shapecue curvature` computes it in (`--order auto`: the bunny's scanned
//! order is renumbered along a Morton curve, the tori's grid order is kept;
//! see `shapecue::mesh::order`).
//! `SHAPECUE_BENCH_QUICK=1` restricts the run to the bunny.
//! `SHAPECUE_DEVICE` picks the device as for the CLI.

mod common;

use criterion::{
    BenchmarkGroup, Criterion, SamplingMode, Throughput, criterion_group, criterion_main,
    measurement::WallTime,
};
use shapecue::Mesh;
use shapecue::gpu::Gpu;
use shapecue::mesh;
use shapecue::mesh::order::MeshOrder;
use shapecue::spec::curvature::CurvatureOptions;
use shapecue::spec::timing::Timing;
use shapecue::stages::curvature::{CurvatureEstimator, OrderedEstimator};
use std::hint::black_box;
use std::sync::Arc;
use std::time::Duration;

/// A bench input: its name, how to make it, and its sampling settings.
struct Input {
    name: &'static str,
    make: fn() -> Option<Mesh>,
    sampling: Sampling,
}

/// Criterion settings for an input. On a 2-core CPU device a run takes
/// about 20 ms on the bunny, 0.2–0.5 s on 500k vertices and 1–2 s on 2M:
/// big inputs get 10 samples with flat sampling (one run per iteration
/// count), sized so that every variant finishes without criterion warnings.
#[derive(Clone, Copy)]
struct Sampling {
    samples: usize,
    flat: bool,
    measure_s: u64,
}

const SMALL: Sampling = Sampling {
    samples: 15,
    flat: false,
    measure_s: 8,
};

/// trimesh2 2.16, one thread, curvature + derivatives of the same meshes on
/// this kind of 2-core machine, ms (the ratio the bench prints).
fn trimesh2_ms(input: &str) -> Option<f64> {
    match input {
        "bunny" => Some(19.7),
        "lucy" => Some(28.7),
        "torus-500k" => Some(253.0),
        "torus-2m" => Some(1014.0),
        _ => None,
    }
}

fn torus_of(n: usize) -> Mesh {
    let (nu, nv) = mesh::torus_resolution_for(n);
    mesh::torus(1.0, 0.4, nu, nv)
}

fn inputs() -> Vec<Input> {
    let mut v = vec![Input {
        name: "bunny",
        make: || common::shared_mesh("curvature", "stanford-bunny.obj"),
        sampling: SMALL,
    }];
    if common::quick() {
        eprintln!("curvature bench: SHAPECUE_BENCH_QUICK set, bunny only");
    } else {
        v.push(Input {
            name: "lucy",
            make: || common::shared_mesh("curvature", "lucy.ply"),
            sampling: SMALL,
        });
        v.push(Input {
            name: "torus-500k",
            make: || Some(torus_of(500_000)),
            sampling: Sampling {
                samples: 10,
                flat: true,
                measure_s: 8,
            },
        });
        v.push(Input {
            name: "torus-2m",
            make: || Some(torus_of(2_000_000)),
            sampling: Sampling {
                samples: 10,
                flat: true,
                measure_s: 20,
            },
        });
    }
    v
}

fn configure(g: &mut BenchmarkGroup<'_, WallTime>, s: Sampling) {
    g.sample_size(s.samples)
        .sampling_mode(if s.flat {
            SamplingMode::Flat
        } else {
            SamplingMode::Linear
        })
        .warm_up_time(Duration::from_secs(1))
        .measurement_time(Duration::from_secs(s.measure_s));
}

/// Builds an estimator for `opts` with `m` on the device and one warm-up run
/// done; `None` (with the reason printed) if the device cannot run it.
fn ready(
    gpu: &Arc<Gpu>,
    m: &Mesh,
    name: &str,
    opts: CurvatureOptions,
) -> Option<CurvatureEstimator> {
    // In the memory order the CLI computes in, pose uploaded.
    let mut est = match OrderedEstimator::new(gpu.clone(), m, opts, MeshOrder::Auto) {
        Ok(o) => o.est,
        Err(e) => {
            eprintln!("curvature bench: skipping {name}: {e}");
            return None;
        }
    };
    // The first run pays for JIT compilation; the second is printed.
    let warm = est.run().and_then(|_| est.run());
    match warm {
        Ok(t) => {
            let passes: Vec<String> = t
                .steps
                .iter()
                .map(|p| format!("{} {:.2}", p.step.name(), p.kernel_ms))
                .collect();
            eprintln!(
                "curvature bench: {name}: kernel {:.2} ms ({}), wall {:.2} ms",
                t.kernel_ms,
                passes.join(", "),
                t.wall_ms
            );
            Some(est)
        }
        Err(e) => {
            eprintln!("curvature bench: skipping {name}: {e}");
            None
        }
    }
}

/// Runs `iters` times and returns the sum of `pick(timing)` (milliseconds) as a duration.
fn timed(est: &mut CurvatureEstimator, iters: u64, pick: fn(&Timing) -> f64) -> Duration {
    let mut ms = 0.0;
    for _ in 0..iters {
        let t = est.run().expect("curvature run failed");
        ms += pick(black_box(&t));
    }
    Duration::from_secs_f64(ms * 1e-3)
}

fn curvature_benches(c: &mut Criterion) {
    let Some(gpu) = common::gpu("curvature") else {
        return;
    };
    // the report's variants, so the README table and the bench cover the same set
    let variants: Vec<(String, _)> = shapecue::report::metrics::variants()
        .into_iter()
        .map(|o| (shapecue::report::metrics::label(&o).replace(' ', "-"), o))
        .collect();
    let mut cpu_input: Option<Mesh> = None;

    for input in inputs() {
        let Some(m) = (input.make)() else { continue };
        eprintln!(
            "curvature bench: {}: {} vertices, {} faces",
            input.name,
            m.n_vertices(),
            m.n_faces()
        );

        let mut g = c.benchmark_group("curvature");
        configure(&mut g, input.sampling);
        g.throughput(Throughput::Elements(m.n_vertices() as u64));
        for (vname, opts) in &variants {
            let opts = *opts;
            let id = format!("{vname}/{}", input.name);
            let Some(mut est) = ready(&gpu, &m, &id, opts) else {
                continue;
            };
            let mut each = Vec::new();
            g.bench_function(&id, |b| {
                b.iter_custom(|iters| {
                    let mut ms = 0.0;
                    for _ in 0..iters {
                        let t = est.run().expect("curvature run failed").kernel_ms;
                        each.push(t);
                        ms += t;
                    }
                    Duration::from_secs_f64(ms * 1e-3)
                })
            });
            // (nothing ran when a filter left this variant out)
            if let Some(t2) = trimesh2_ms(input.name).filter(|_| !each.is_empty()) {
                let k = shapecue::report::metrics::median(&mut each);
                eprintln!(
                    "curvature/{id}: kernel median {k:.2} ms, {:.1}× faster than trimesh2's {t2} ms",
                    t2 / k
                );
            }
        }
        g.finish();

        let mut g = c.benchmark_group("curvature");
        configure(&mut g, input.sampling);
        g.throughput(Throughput::Elements(m.n_vertices() as u64));
        let (vname, opts) = (&variants[0].0, variants[0].1);
        let id = format!("{vname}-wall/{}", input.name);
        if let Some(mut est) = ready(&gpu, &m, &id, opts) {
            g.bench_function(&id, |b| {
                b.iter_custom(|iters| timed(&mut est, iters, |t| t.wall_ms))
            });
        }
        g.finish();

        if input.name == "bunny" {
            cpu_input = Some(m);
        }
    }

    if let Some(m) = cpu_input {
        let mut g = c.benchmark_group("curvature");
        g.sample_size(10)
            .warm_up_time(Duration::from_secs(1))
            .measurement_time(Duration::from_secs(5))
            .throughput(Throughput::Elements(m.n_vertices() as u64));
        let opts = CurvatureOptions::default();
        g.bench_function("cpu-reference/bunny", |b| {
            b.iter(|| shapecue::cpu::curvature::estimate(black_box(&m), &opts))
        });
        g.finish();
    }
}

criterion_group!(benches, curvature_benches);
criterion_main!(benches);
