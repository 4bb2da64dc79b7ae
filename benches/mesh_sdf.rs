//! Criterion groups `mesh_sdf/<variant>/<input>`: the Stanford bunny
//! (skipped with a message when `../shared/data` is absent) converted to a
//! signed distance field at 128³ on the device (`device`, program built
//! once, prepared mesh uploaded each iteration) and by the CPU twin
//! (`cpu`). Kernel-only medians of the device passes are printed.

use criterion::{Criterion, criterion_group, criterion_main};
use shapecue::cpu::mesh_sdf as cpu;
use shapecue::gpu::Gpu;
use shapecue::mesh::mesh_sdf::prepare;
use shapecue::report::metrics::median;
use shapecue::spec::mesh_sdf::MeshSdfOptions;
use shapecue::stages::mesh_sdf::MeshSdf;
use std::path::Path;
use std::sync::Arc;
use std::time::Duration;

fn bench(c: &mut Criterion) {
    let path =
        Path::new(env!("CARGO_MANIFEST_DIR")).join("../shared/data/meshes/stanford-bunny.obj");
    if !path.exists() {
        eprintln!("skipping: {} not found", path.display());
        return;
    }
    let mesh = shapecue::mesh::load(&path, &Default::default()).expect("bunny loads");
    let gpu = Arc::new(Gpu::new(None).expect("an OpenCL device (PoCL is enough)"));
    let res = 128;
    let prep = prepare(&mesh, &MeshSdfOptions { resolution: res }, "bunny").expect("prepare");
    let mut dev = MeshSdf::new(gpu).expect("kernels");
    let mut g = c.benchmark_group("mesh_sdf");
    g.sample_size(10).measurement_time(Duration::from_secs(10));
    let mut kernel_ms = Vec::new();
    g.bench_function(format!("device/bunny-{res}"), |b| {
        b.iter(|| kernel_ms.push(dev.run(&prep).expect("device run").1.timing.kernel_ms))
    });
    g.bench_function(format!("cpu/bunny-{res}"), |b| b.iter(|| cpu::run(&prep)));
    g.finish();
    eprintln!(
        "mesh_sdf/device/bunny-{res}: kernel median {:.1} ms",
        median(&mut kernel_ms)
    );
}

criterion_group!(benches, bench);
criterion_main!(benches);
