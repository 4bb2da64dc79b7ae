//! Exact visibility benches (`src/stages/visibility.rs` over
//! `kernels/bvh.cl`, twin `src/cpu/visibility.rs`; chains
//! `src/spec/chains.rs`): what one view of a line drawing pays after its
//! line kernels.
//!
//! On the Stanford bunny (shared data; skipped with a message where
//! absent), every line family, one perspective view from (1, 0.6, 0.8) at
//! 480 × 360 (the first view of `tests/visibility_meshes.rs`), host wall
//! time:
//! - `visibility/classify/bunny`: `stages::visibility::classify` (order,
//!   plan, the sample round and the bisection rounds, transfers);
//! - `visibility/plan/bunny`: `spec::visibility_plan::RayPlan::new` alone (the
//!   segments in Morton order, as `classify` takes them);
//! - `visibility/chains/bunny`: `spec::chains::chain` over the classified
//!   pieces (keyed by `spec::chains::chain_pieces`, as the vector drawing
//!   keys them: mesh edge, vertex, or a cut where visibility changes).
//!
//! The curvature and the segments are computed once, before the groups.
//! `SHAPECUE_DEVICE` picks the device as for the CLI.

mod common;

use criterion::{Criterion, criterion_group, criterion_main};
use glam::Vec3;
use shapecue::api::LineSetup;
use shapecue::render::Camera;
use shapecue::spec::chains::{chain, chain_pieces};
use shapecue::spec::curvature::CurvatureOptions;
use shapecue::spec::feature_lines::{FamilySet, LineFamily, Segment};
use shapecue::spec::visibility::VisibilityOptions;
use shapecue::spec::visibility_plan::RayPlan;
use shapecue::stages::bvh::Bvh;
use shapecue::stages::curvature::CurvatureEstimator;
use shapecue::stages::feature_lines::{LineExtractor, LineOptions};
use shapecue::stages::visibility::{classify, spatial_order};
use std::hint::black_box;
use std::time::Duration;

const W: u32 = 480;
const H: u32 = 360;

fn bench(c: &mut Criterion) {
    let Some(gpu) = common::gpu("visibility") else {
        return;
    };
    let Some(m) = common::shared_mesh("visibility", "stanford-bunny.obj") else {
        return;
    };
    let p: Vec<[f32; 3]> = (m.positions.iter()).map(|q| q.map(|c| c as f32)).collect();
    let (lo, hi) = p
        .iter()
        .fold((Vec3::INFINITY, Vec3::NEG_INFINITY), |(a, b), q| {
            (a.min(Vec3::from(*q)), b.max(Vec3::from(*q)))
        });
    let cam = Camera::fit(lo, hi, Vec3::new(1.0, 0.6, 0.8), W as f32 / H as f32).expect("camera");
    let view = cam.view(W, H);
    let setup = LineSetup::default();
    let copts = CurvatureOptions {
        dcurv: true,
        ..setup.curvature
    };
    let mut est =
        CurvatureEstimator::new(gpu.clone(), m.n_vertices(), &m.faces, copts).expect("est");
    est.set_positions(&m.positions).expect("positions");
    est.run().expect("curvature");
    let fs = (est.feature_size(setup.feature_size, &m.positions, &m.faces)).expect("feature size");
    let mut ex = LineExtractor::new(gpu.clone(), m.n_vertices(), &m.faces).expect("extractor");
    let mut opts = LineOptions {
        contours: true,
        suggestive: true,
        ..Default::default()
    };
    opts.curves.families = FamilySet::of(&LineFamily::ALL).curves();
    let (segs, _) = (ex.extract_device(&est, view, fs as f32, opts)).expect("lines");
    let mut bvh = Bvh::new(gpu, p.len(), &m.faces).expect("bvh");
    bvh.build(&p).expect("build");
    let vopts = VisibilityOptions::default();
    let order = spatial_order(&segs);
    let sorted: Vec<Segment> = order.iter().map(|&i| segs[i]).collect();
    let (pieces, _) = classify(&mut bvh, &p, &m.faces, &sorted, &view, &vopts).expect("classify");
    // Ends inside faces keyed on the grid of the mesh's largest extent, as
    // the vector drawing keys them.
    let cps = chain_pieces(&sorted, &pieces, (hi - lo).max_element());
    eprintln!(
        "visibility bench: bunny, {} segments, {} pieces",
        segs.len(),
        cps.len()
    );

    let mut g = c.benchmark_group("visibility");
    g.sample_size(10)
        .warm_up_time(Duration::from_secs(1))
        .measurement_time(Duration::from_secs(4));
    g.bench_function("classify/bunny", |b| {
        b.iter(|| {
            classify(&mut bvh, &p, &m.faces, black_box(&segs), &view, &vopts).expect("classify")
        })
    });
    g.bench_function("plan/bunny", |b| {
        b.iter(|| RayPlan::new(&p, &m.faces, black_box(&sorted), &view, &vopts).expect("plan"))
    });
    g.bench_function("chains/bunny", |b| b.iter(|| chain(black_box(&cps))));
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
