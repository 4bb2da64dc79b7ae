//! Criterion groups `skinning/<stage>/<model>` on the shared glTF models
//! (skipped with a message when `../shared/data` is absent): the skinning
//! kernel alone (`skin`), and the per-frame device pipeline that exists so
//! far, skinning then every curvature pass with dcurv on the skinned
//! positions without a host round trip (`skin+curvature`). Frames step
//! through the first clip. Kernel-only medians are printed per model.

mod common;

use criterion::{Criterion, criterion_group, criterion_main};
use shapecue::mesh::skinned::{SkinnedMesh, load_gltf};
use shapecue::report::metrics::median;
use shapecue::spec::curvature::{Accumulate, Compat, CurvatureOptions, Normalization, Precision};
use shapecue::stages::curvature::CurvatureEstimator;
use shapecue::stages::skinning::Skinner;
use std::time::Duration;

fn bench(c: &mut Criterion) {
    let Some(dir) = common::shared("skinning", "animations/gltf") else {
        return;
    };
    let Some(gpu) = common::gpu("skinning") else {
        return;
    };
    for name in ["BrainStem", "CesiumMan", "Fox"] {
        let m = load_gltf(&dir.join(format!("{name}.glb"))).expect("model loads");
        let clip = &m.clips[0];
        let frames: Vec<Vec<f32>> = (0..30)
            .map(|f| {
                let t = clip.duration * f as f32 / 30.0;
                SkinnedMesh::flatten(&m.joint_matrices(Some(0), t).expect("pose"))
            })
            .collect();
        let mut sk = Skinner::new(gpu.clone(), &m).expect("skinner");
        let opts = CurvatureOptions {
            accumulate: Accumulate::Atomic,
            precision: Precision::F32,
            compat: Compat::Exact,
            dcurv: true,
            lanes: shapecue::spec::curvature::Lanes::Auto,
        };
        let mut est =
            CurvatureEstimator::new(gpu.clone(), m.rest.positions.len(), &m.rest.faces, opts)
                .expect("estimator");
        let norm = Normalization::of(&m.rest.positions);
        let mut g = c.benchmark_group("skinning");
        g.sample_size(20).measurement_time(Duration::from_secs(3));
        let mut i = 0;
        let mut skin_ms = Vec::new();
        g.bench_function(format!("skin/{name}"), |b| {
            b.iter(|| {
                i = (i + 1) % frames.len();
                skin_ms.push(sk.pose(&frames[i]).expect("skin"));
            })
        });
        let mut total_ms = Vec::new();
        g.bench_function(format!("skin+curvature/{name}"), |b| {
            b.iter(|| {
                i = (i + 1) % frames.len();
                let s = sk.pose(&frames[i]).expect("skin");
                est.set_positions_device(&sk.out, [1.0; 3], [0.0; 3], norm)
                    .expect("positions");
                total_ms.push(s + est.run().expect("curvature").kernel_ms);
            })
        });
        g.finish();
        eprintln!(
            "skinning/{name}: {} vertices; kernel medians: skin {:.3} ms, skin + curvature (dcurv) {:.2} ms",
            m.rest.positions.len(),
            median(&mut skin_ms),
            median(&mut total_ms)
        );
    }
}

criterion_group!(benches, bench);
criterion_main!(benches);
