use shapecue::field::*;
use std::sync::Arc;
fn main() {
    let gpu = Arc::new(shapecue::gpu::Gpu::new(None).unwrap());
    let m = shapecue::mesh::load(std::path::Path::new("../shared/data/meshes/stanford-bunny.obj"), &Default::default()).unwrap();
    for o in [CurvatureOptions::default(), CurvatureOptions{accumulate: Accumulate::Gather, ..Default::default()}] {
        let mut est = shapecue::stages::curvature::CurvatureEstimator::new(gpu.clone(), m.n_vertices(), &m.faces, o).unwrap();
        est.set_positions(&m.positions).unwrap();
        est.run().unwrap();
        let mut v = vec![];
        let mut last = None;
        for _ in 0..15 { let t = est.run().unwrap(); v.push(t.kernel_ms); last = Some(t); }
        v.sort_by(|a,b| a.partial_cmp(b).unwrap());
        println!("{:?}: median {:.2} ms  {:?}", o.accumulate, v[7], last.unwrap().passes.iter().map(|p| format!("{}={:.2}", p.pass, p.kernel_ms)).collect::<Vec<_>>());
    }
}
