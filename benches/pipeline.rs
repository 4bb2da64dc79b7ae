//! Criterion group `pipeline/total/<model>` on the shared glTF models
//! (skipped with a message when `../shared/data` is absent): one frame of the
//! default per-pose device pipeline
//! ([`shapecue::stages::pipeline::PosePipeline::frame`], the code behind
//! `shapecue report pipeline`): skin, curvature with dcurv (f32,
//! atomic), AO (`lut`), contours + suggestive contours from one perspective
//! view, chained on the device; per frame only the joint matrices go up and
//! the segments come back. Frames step through the first clip. Per model the
//! per-pass kernel-ms medians, their total and the wall-clock median are
//! printed, with the 16 ms frame budget of the issue.

mod common;

use criterion::{Criterion, criterion_group, criterion_main};
use shapecue::mesh::skinned::load_gltf;
use shapecue::report::metrics::median;
use shapecue::spec::timing::Family;
use shapecue::stages::feature_lines::LineOptions;
use shapecue::stages::pipeline::{PassTimes, PipelineOptions, PosePipeline, clip_poses};
use std::time::Duration;

fn bench(c: &mut Criterion) {
    if common::shared("pipeline", "animations/gltf").is_none() {
        return;
    }
    let Some(gpu) = common::gpu("pipeline") else {
        return;
    };
    let mut g = c.benchmark_group("pipeline");
    g.sample_size(20).measurement_time(Duration::from_secs(4));
    for name in ["BrainStem", "CesiumMan", "Fox"] {
        let Some(path) = common::shared("pipeline", format!("animations/gltf/{name}.glb")) else {
            continue;
        };
        let m = load_gltf(&path).expect("model loads");
        let frames = clip_poses(&m, 30).expect("poses");
        let mut p =
            PosePipeline::new(gpu.clone(), &m, PipelineOptions::default()).expect("pipeline");
        let (view, size, opts) = (p.front_view(), p.feature_size(), LineOptions::default());
        let mut times: Vec<PassTimes> = Vec::new();
        let mut i = 0;
        g.bench_function(format!("total/{name}"), |b| {
            b.iter(|| {
                i = (i + 1) % frames.len();
                let (segs, t) = p.frame(&frames[i], view, size, opts).expect("frame");
                times.push(t);
                segs
            })
        });
        let med = |f: fn(&PassTimes) -> f64| median(&mut times.iter().map(f).collect::<Vec<_>>());
        let (total, wall) = (med(|t| t.kernel_ms), med(|t| t.wall_ms));
        eprintln!(
            "pipeline/{name}: {} vertices, {} frames timed; kernel medians: skin {:.3} ms, \
             curvature+dcurv {:.3} ms, ao lut {:.3} ms, lines {:.3} ms, total {total:.3} ms; \
             wall {wall:.3} ms per frame; 16 ms budget {}",
            m.rest.positions.len(),
            times.len(),
            med(|t| t.family_ms(Family::Skinning)),
            med(|t| t.family_ms(Family::Curvature)),
            med(|t| t.family_ms(Family::Ao)),
            med(|t| t.family_ms(Family::FeatureLines)),
            if wall <= 16.0 { "met" } else { "NOT met" }
        );
    }
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
