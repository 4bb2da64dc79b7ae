//! The Rust side of the Python call-overhead figure: the median wall time of
//! `shapecue::curvature_on` on a device opened once (what the Python
//! binding does per thread), on a mesh file, with the default options.
//! `python/bench/overhead.py` times the Python call on the same file and
//! prints both.
//!
//! ```sh
//! cargo run --release --manifest-path python/Cargo.toml --example overhead -- MESH RUNS
//! ```

use shapecue::gpu::Gpu;
use shapecue::mesh::LoadOptions;
use shapecue::spec::curvature::CurvatureOptions;
use std::sync::Arc;
use std::time::Instant;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let mut args = std::env::args().skip(1);
    let path = args.next().ok_or("usage: overhead MESH [RUNS]")?;
    let runs: usize = args.next().map(|s| s.parse()).transpose()?.unwrap_or(21);
    let mesh = shapecue::mesh::load(path.as_ref(), &LoadOptions::default())?;
    let gpu = Arc::new(Gpu::new(None)?);
    let opts = CurvatureOptions::default();
    shapecue::curvature_on(&gpu, &mesh, opts)?; // builds the programs
    let mut ms: Vec<f64> = (0..runs)
        .map(|_| {
            let t = Instant::now();
            let c = shapecue::curvature_on(&gpu, &mesh, opts).expect("curvature");
            std::hint::black_box(&c);
            t.elapsed().as_secs_f64() * 1e3
        })
        .collect();
    ms.sort_by(f64::total_cmp);
    println!("{}", ms[ms.len() / 2]);
    Ok(())
}
