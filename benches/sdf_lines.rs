//! Criterion groups `sdf_lines/<step>/<input>`: the whole family
//! (`sdf_lines/all/<input>`: dense samples → thinning → curvature → range →
//! trace → strips, sampling distance fixed, volume and gradient already on
//! the device) and its steps measured through the device API
//! (`dense`, `thin`, `curvature`), on the torus and gyroid SDFs at 128³.
//! The per-step kernel ms of one run are printed from the stats.

use criterion::{Criterion, criterion_group, criterion_main};
use shapecue::gpu::Gpu;
use shapecue::spec::sdf_lines::{Sampling, SdfLineOptions};
use shapecue::stages::sdf_lines::SdfLines;
use shapecue::volume::sdf::{Sdf, sdf};
use std::sync::Arc;
use std::time::Duration;

fn bench(c: &mut Criterion) {
    let gpu = Arc::new(Gpu::new(None).expect("an OpenCL device (PoCL is enough)"));
    for (name, kind) in [("torus-128", Sdf::Torus), ("gyroid-128", Sdf::Gyroid)] {
        let vol = sdf(kind, 128);
        let h = 3.0 * vol.spacing[0];
        let opts = SdfLineOptions {
            sampling: Sampling::Fixed(h),
            ..Default::default()
        };
        let mut s = SdfLines::new(gpu.clone(), &vol, &opts).expect("upload");
        let out = s.run().expect("run");
        eprintln!("{name}: {:?}", out.stats.timing);
        let mut g = c.benchmark_group("sdf_lines");
        g.sample_size(10).measurement_time(Duration::from_secs(5));
        g.bench_function(format!("all/{name}"), |b| b.iter(|| s.run().expect("run")));
        let r = out.stats.params.expect("params").spacing;
        g.bench_function(format!("thin/{name}"), |b| {
            b.iter(|| s.thin(r).expect("thin"))
        });
        let seeds = s.thin(r).expect("thin");
        g.bench_function(format!("curvature/{name}"), |b| {
            b.iter(|| s.curvature_at(&seeds, h).expect("curvature"))
        });
        let fresh = || SdfLines::new(gpu.clone(), &vol, &opts).expect("upload");
        g.bench_function(format!("dense/{name}"), |b| {
            b.iter(|| fresh().dense().expect("dense"))
        });
        g.finish();
    }
}

criterion_group!(benches, bench);
criterion_main!(benches);
