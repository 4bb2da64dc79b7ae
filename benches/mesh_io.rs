//! Mesh file input and output benches (`src/mesh/load/`, `src/export/ply.rs`):
//! the host-side phases of a `shapecue curvature IN -o OUT.ply` process
//! besides the device work, which the `curvature` bench measures.
//!
//! Groups:
//! - `mesh_io/load/<input>`: [`shapecue::mesh::load`] (read the file, parse,
//!   validate) of the Stanford bunny (OBJ, 2.4 MB) and lucy (binary PLY,
//!   1.9 MB) from `shared/data/meshes` (each skipped if absent) and of a
//!   generated 500k-vertex torus written to a temporary folder as OBJ and as
//!   the binary PLY with 19 float properties that `shapecue curvature -o`
//!   writes.
//! - `mesh_io/write-curvature-ply/bunny`: [`shapecue::export::ply::write_ply`]
//!   of the bunny with its 16 curvature properties (from the CPU twin), as
//!   the CLI writes it: to a temporary file, synced, renamed over the output.
//!
//! `SHAPECUE_BENCH_QUICK=1` drops the generated torus.

mod common;

use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use shapecue::Mesh;
use shapecue::mesh::{self, LoadOptions};
use shapecue::spec::curvature::{CurvatureField, CurvatureOptions};
use std::hint::black_box;
use std::io::Write;
use std::path::{Path, PathBuf};
use std::time::Duration;

/// Writes `m` as a plain OBJ (`v x y z`, `f a b c`) to `path`.
fn write_obj(path: &Path, m: &Mesh) -> std::io::Result<()> {
    let mut w = std::io::BufWriter::new(std::fs::File::create(path)?);
    for p in &m.positions {
        writeln!(w, "v {} {} {}", p[0], p[1], p[2])?;
    }
    for f in &m.faces {
        writeln!(w, "f {} {} {}", f[0] + 1, f[1] + 1, f[2] + 1)?;
    }
    w.flush()
}

fn bench_load(c: &mut Criterion, tmp: &Path) {
    let mut inputs: Vec<(&str, PathBuf)> = Vec::new();
    for (name, file) in [
        ("bunny-obj", "stanford-bunny.obj"),
        ("lucy-ply", "lucy.ply"),
    ] {
        if let Some(p) = common::shared("mesh_io", Path::new("meshes").join(file)) {
            inputs.push((name, p));
        }
    }
    if !common::quick() {
        let (nu, nv) = mesh::torus_resolution_for(500_000);
        let torus = mesh::torus(1.0, 0.4, nu, nv);
        let p = tmp.join("torus-500k.obj");
        match write_obj(&p, &torus) {
            Ok(()) => inputs.push(("torus-500k-obj", p)),
            Err(e) => eprintln!("mesh_io bench: cannot write {}: {e}", p.display()),
        }
        // As `shapecue curvature -o` writes it: 19 float properties (zeros:
        // the values do not change the file's size).
        let p = tmp.join("torus-500k.ply");
        match shapecue::export::ply::write_ply(
            &p,
            &torus,
            Some(&CurvatureField::zeros(torus.n_vertices())),
        ) {
            Ok(_) => inputs.push(("torus-500k-curvature-ply", p)),
            Err(e) => eprintln!("mesh_io bench: cannot write {}: {e}", p.display()),
        }
    }
    let mut g = c.benchmark_group("mesh_io/load");
    g.sample_size(20).measurement_time(Duration::from_secs(6));
    for (name, path) in &inputs {
        let bytes = std::fs::metadata(path).map_or(0, |m| m.len());
        g.throughput(Throughput::Bytes(bytes));
        g.bench_function(*name, |b| {
            b.iter(|| black_box(mesh::load(path, &LoadOptions::default()).expect("load")))
        });
    }
    g.finish();
}

fn bench_write(c: &mut Criterion, tmp: &Path) {
    let Some(bunny) = common::shared_mesh("mesh_io", "stanford-bunny.obj") else {
        return;
    };
    let field = shapecue::cpu::curvature::curvature(&bunny, CurvatureOptions::default())
        .expect("CPU curvature")
        .field;
    let out = tmp.join("bunny-curvature.ply");
    let mut g = c.benchmark_group("mesh_io/write-curvature-ply");
    g.sample_size(20).measurement_time(Duration::from_secs(6));
    g.bench_function("bunny", |b| {
        b.iter(|| {
            black_box(shapecue::export::ply::write_ply(&out, &bunny, Some(&field)).expect("write"))
        })
    });
    g.finish();
}

fn benches(c: &mut Criterion) {
    let tmp = std::env::temp_dir().join(format!("shapecue-mesh-io-bench-{}", std::process::id()));
    if let Err(e) = std::fs::create_dir_all(&tmp) {
        eprintln!(
            "mesh_io bench: cannot create {}: {e}; nothing to bench",
            tmp.display()
        );
        return;
    }
    bench_load(c, &tmp);
    bench_write(c, &tmp);
    let _ = std::fs::remove_dir_all(&tmp);
}

criterion_group!(mesh_io, benches);
criterion_main!(mesh_io);
