//! Criterion groups `isosurface/<fusion>/<volume>` (fusion: direct, edge,
//! hash, none): marching cubes + vertex fusion with the volume already on the
//! device (wall time of one
//! extraction, which ends with the counts read back), for the procedural
//! SDFs at 128³ and 256³ and the real volumes of `../shared/data/volumes`
//! (skipped with a message when absent). Kernel-only medians are printed
//! per input. `SHAPECUE_BENCH_QUICK=1` keeps the 128³ fields only.
//! 512³ is measured by `shapecue report isosurface`, not here.

mod common;

use criterion::{Criterion, criterion_group, criterion_main};
use shapecue::report::metrics::median;
use shapecue::spec::vertex_fusion::Fusion;
use shapecue::stages::marching_cubes::Isosurfacer;
use shapecue::volume::sdf::{Sdf, sdf};
use shapecue::volume::{self, RawSpec, ScalarType, Volume};
use std::time::Duration;

fn inputs() -> Vec<(String, Volume, f32)> {
    let quick = common::quick();
    let mut v = Vec::new();
    for res in [128, 256] {
        if quick && res > 128 {
            continue;
        }
        for (name, kind) in [
            ("sphere", Sdf::Sphere),
            ("torus", Sdf::Torus),
            ("gyroid", Sdf::Gyroid),
        ] {
            v.push((format!("{name}-{res}"), sdf(kind, res), 0.0));
        }
    }
    let Some(dir) = common::shared("isosurface", "volumes") else {
        return v;
    };
    let bucky = RawSpec::new([32; 3], ScalarType::U8);
    for (file, iso, raw) in [
        ("Bucky.raw", 51.0, Some(&bucky)),
        ("ironProt.vtk", 128.0, None),
        ("headsq/quarter.nhdr", 500.0, None),
        ("HeadMRVolume.mhd", 100.0, None),
        ("hydrogen.vti", 0.1, None),
        ("neghip.slc", 128.0, None),
    ] {
        match volume::load(&dir.join(file), raw) {
            Ok(vol) => v.push((file.replace('/', "-"), vol, iso)),
            Err(e) => eprintln!("skipping {file}: {e}"),
        }
    }
    v
}

fn bench(c: &mut Criterion) {
    let Some(gpu) = common::gpu("isosurface") else {
        return;
    };
    for (name, vol, iso) in inputs() {
        let mut ex = Isosurfacer::new(gpu.clone(), &vol).expect("upload");
        for fusion in Fusion::ALL {
            let mut g = c.benchmark_group(format!("isosurface/{}", fusion.name()));
            g.sample_size(10).measurement_time(Duration::from_secs(3));
            let mut kernel = Vec::new();
            g.bench_function(&name, |b| {
                b.iter(|| {
                    let st = ex.extract(iso, fusion).expect("extract");
                    kernel.push(st.timing.kernel_ms);
                })
            });
            g.finish();
            let st = ex.extract(iso, fusion).expect("extract");
            let k = median(&mut kernel);
            eprintln!(
                "isosurface/{}/{name}: kernel median {k:.2} ms; {} soup vertices → {} vertices, {} faces, {} dropped",
                fusion.name(),
                st.soup_vertices,
                st.vertices,
                st.faces,
                st.degenerate_dropped
            );
        }
    }
}

criterion_group!(benches, bench);
criterion_main!(benches);
