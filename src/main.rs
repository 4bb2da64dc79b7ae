//! The `shapecue` command line: thin; parses, calls the library, reports.

use anyhow::{Context, Result, bail};
use clap::{Args, Parser, Subcommand, ValueEnum};
use shapecue::field::{Accumulate, Compat, CurvatureOptions, Precision};
use shapecue::gpu::{Gpu, list_devices};
use shapecue::mesh::{LoadOptions, Mesh};
use shapecue::report;
use shapecue::stages::curvature::CurvatureEstimator;
use std::path::{Path, PathBuf};
use std::sync::Arc;
use std::time::Instant;

#[derive(Parser)]
#[command(
    name = "shapecue",
    version,
    about = "Shape cues (curvature, ...) computed by OpenCL kernels"
)]
struct Cli {
    /// OpenCL device: index from `shapecue devices` or a name substring
    /// (default: first GPU, else first CPU device).
    #[arg(long, global = true, env = "SHAPECUE_DEVICE")]
    device: Option<String>,
    #[command(subcommand)]
    cmd: Cmd,
}

#[derive(Subcommand)]
enum Cmd {
    /// List OpenCL platforms and devices.
    Devices {
        /// Print JSON instead of a table.
        #[arg(long)]
        json: bool,
    },
    /// Per-vertex normals, areas, principal curvatures and directions, and the
    /// curvature derivative, written as binary PLY.
    Curvature(CurvatureArgs),
    /// Isosurface of a volume (marching cubes with vertex fusion on the
    /// device), optionally with curvature computed on the device right after.
    Isosurface(IsoArgs),
}

#[derive(Clone, Copy, ValueEnum)]
enum NormalsArg {
    Gradient,
    Mesh,
}

#[derive(Clone, Copy, ValueEnum)]
enum FusionArg {
    Hash,
    Edge,
    None,
}

#[derive(Args)]
struct IsoArgs {
    /// Input volume: .nrrd/.nhdr, .mhd/.mha, .vtk (STRUCTURED_POINTS), .vti, or
    /// raw data with --dims and --type.
    #[arg(required_unless_present_any = ["sdf", "report"])]
    input: Option<PathBuf>,
    /// Use a procedural signed distance field instead: sphere, torus or gyroid.
    #[arg(long, conflicts_with = "input")]
    sdf: Option<String>,
    /// Grid points per axis of a procedural field.
    #[arg(long, default_value_t = 128)]
    resolution: usize,
    /// Iso value (default 0 for procedural fields).
    #[arg(long, allow_negative_numbers = true)]
    iso: Option<f32>,
    /// Raw input: voxels per axis, e.g. 32,32,32.
    #[arg(long, value_delimiter = ',')]
    dims: Option<Vec<usize>>,
    /// Raw input: voxel type (u8, i8, u16, i16, u32, i32, f32, f64).
    #[arg(long = "type")]
    scalar: Option<String>,
    /// Raw input: big-endian data.
    #[arg(long)]
    big_endian: bool,
    /// Raw input: world units per voxel step, e.g. 1,1,2.5.
    #[arg(long, value_delimiter = ',')]
    spacing: Option<Vec<f64>>,
    /// Raw input: bytes to skip before the data.
    #[arg(long, default_value_t = 0)]
    header_bytes: usize,
    /// Vertex fusion: hash (the seed's position hash + radix sort), edge
    /// (exact voxel-edge keys), none (triangle soup).
    #[arg(long, value_enum, default_value = "hash")]
    fusion: FusionArg,
    /// Write per-vertex normals from the volume gradient.
    #[arg(long)]
    normals: bool,
    /// Compute curvature on the device right after extraction (no host round trip).
    #[arg(long)]
    curvature: bool,
    /// Curvature precision.
    #[arg(long, value_enum, default_value = "f32")]
    precision: PrecArg,
    /// Vertex normals of the curvature passes: the volume gradient (accurate
    /// on marching-cubes meshes) or the mesh's own face normals (the paper's).
    #[arg(long, value_enum, default_value = "gradient")]
    curvature_normals: NormalsArg,
    /// Skip the curvature-derivative pass.
    #[arg(long)]
    no_dcurv: bool,
    /// Output PLY (binary little-endian). Never the input file.
    #[arg(short, long)]
    output: Option<PathBuf>,
    /// Write statistics (passes, counts, quality, bytes) as JSON.
    #[arg(long)]
    stats: Option<PathBuf>,
    /// Overwrite existing output files.
    #[arg(long)]
    force: bool,
    /// Print the isosurface accuracy/time report instead (no input needed).
    #[arg(long)]
    report: bool,
    /// Largest resolution of the report's sweep.
    #[arg(long, default_value_t = 512)]
    max_resolution: usize,
    /// Runs per measurement in the report (median).
    #[arg(long, default_value_t = 5)]
    runs: usize,
}

#[derive(Clone, Copy, ValueEnum)]
enum AccArg {
    Atomic,
    Gather,
}
#[derive(Clone, Copy, ValueEnum)]
enum PrecArg {
    F32,
    F64,
}
#[derive(Clone, Copy, ValueEnum)]
enum CompatArg {
    Exact,
    Trimesh2,
}
#[derive(Clone, Copy, ValueEnum)]
enum GenArg {
    Torus,
    Sphere,
    Ellipsoid,
    Cylinder,
    Plane,
}

#[derive(Args)]
struct CurvatureArgs {
    /// Input mesh (.obj, .ply, .off).
    #[arg(required_unless_present_any = ["generate", "report"])]
    input: Option<PathBuf>,
    /// Use a generated mesh instead of a file.
    #[arg(long, value_enum, conflicts_with = "input")]
    generate: Option<GenArg>,
    /// Approximate vertex count of a generated mesh.
    #[arg(long, default_value_t = 40_000)]
    resolution: usize,
    /// Output PLY (binary little-endian). Never the input file.
    #[arg(short, long)]
    output: Option<PathBuf>,
    /// Merge vertices with bit-identical positions before computing.
    #[arg(long)]
    weld: bool,
    /// One-ring accumulation: float atomics per face, or per-vertex gather (deterministic).
    #[arg(long, value_enum, default_value = "atomic")]
    accumulate: AccArg,
    /// Device precision.
    #[arg(long, value_enum, default_value = "f32")]
    precision: PrecArg,
    /// Exact least squares, or trimesh2 2.16 compatibility (its pivot quirk, |k1| ≥ |k2|).
    #[arg(long, value_enum, default_value = "exact")]
    compat: CompatArg,
    /// Skip the curvature-derivative pass (dk written as zeros).
    #[arg(long)]
    no_dcurv: bool,
    /// Compute with the CPU reference instead of the device.
    #[arg(long)]
    cpu: bool,
    /// Write statistics (device, counts, per-pass ms, bytes) as JSON.
    #[arg(long)]
    stats: Option<PathBuf>,
    /// Overwrite existing output files.
    #[arg(long)]
    force: bool,
    /// Print the accuracy/time table of every variant instead (no input needed).
    #[arg(long)]
    report: bool,
    /// Runs per variant for the report's median times.
    #[arg(long, default_value_t = 7)]
    runs: usize,
}

fn main() {
    if let Err(e) = run() {
        eprintln!("error: {e:#}");
        std::process::exit(1);
    }
}

fn run() -> Result<()> {
    let cli = Cli::parse();
    match cli.cmd {
        Cmd::Devices { json } => devices(json),
        Cmd::Curvature(a) => curvature(cli.device.as_deref(), a),
        Cmd::Isosurface(a) => isosurface(cli.device.as_deref(), a),
    }
}

fn devices(json: bool) -> Result<()> {
    let devs = list_devices()?;
    if json {
        println!("{}", serde_json::to_string_pretty(&devs)?);
        return Ok(());
    }
    let default = shapecue::gpu::Gpu::new(None).ok().map(|g| g.info.index);
    println!(
        "{:>3}  {:<4} {:>3} {:>9} {:>4} {:>10} {:>9}  platform / device",
        "#", "type", "CUs", "memory", "fp64", "gl_sharing", "int64_atm"
    );
    for d in devs {
        let yn = |b: bool| if b { "yes" } else { "no" };
        println!(
            "{:>3}{} {:<4} {:>3} {:>6} MiB {:>4} {:>10} {:>9}  {} / {} ({})",
            d.index,
            if Some(d.index) == default { "*" } else { " " },
            d.kind,
            d.compute_units,
            d.global_mem >> 20,
            yn(d.fp64),
            yn(d.gl_sharing),
            yn(d.int64_atomics),
            d.platform,
            d.name,
            d.version
        );
    }
    println!("(* = default; choose with --device <index|name> or SHAPECUE_DEVICE)");
    Ok(())
}

fn options(a: &CurvatureArgs) -> CurvatureOptions {
    CurvatureOptions {
        accumulate: match a.accumulate {
            AccArg::Atomic => Accumulate::Atomic,
            AccArg::Gather => Accumulate::Gather,
        },
        precision: match a.precision {
            PrecArg::F32 => Precision::F32,
            PrecArg::F64 => Precision::F64,
        },
        compat: match a.compat {
            CompatArg::Exact => Compat::Exact,
            CompatArg::Trimesh2 => Compat::Trimesh2,
        },
        dcurv: !a.no_dcurv,
    }
}

fn generated(kind: GenArg, n: usize) -> (String, Mesh) {
    use shapecue::mesh as g;
    let level = |n: usize| {
        let mut l = 0;
        while 10 * 4usize.pow(l + 1) + 2 <= n && l < 10 {
            l += 1;
        }
        l
    };
    match kind {
        GenArg::Torus => {
            let (nu, nv) = g::torus_resolution_for(n);
            (
                format!("torus R=1 r=0.4 {nu}x{nv}"),
                g::torus(1.0, 0.4, nu, nv),
            )
        }
        GenArg::Sphere => (
            format!("icosphere level {}", level(n)),
            g::icosphere(1.0, level(n)),
        ),
        GenArg::Ellipsoid => (
            format!("ellipsoid 1.5,1,0.6 level {}", level(n)),
            g::ellipsoid(1.5, 1.0, 0.6, level(n)),
        ),
        GenArg::Cylinder => {
            let k = ((n as f64).sqrt() as usize).max(3);
            (format!("cylinder {k}x{k}"), g::cylinder(1.0, 2.0, k, k))
        }
        GenArg::Plane => {
            let k = ((n as f64).sqrt() as usize).max(2);
            (format!("plane {k}x{k}"), g::plane(k, 2.0))
        }
    }
}

fn refuse_overwrite(out: &Path, input: Option<&Path>, force: bool) -> Result<()> {
    if let Some(inp) = input {
        let same = match (out.canonicalize(), inp.canonicalize()) {
            (Ok(a), Ok(b)) => a == b,
            _ => out == inp,
        };
        if same {
            bail!("refusing to write {}: it is the input file", out.display());
        }
    }
    if out.exists() && !force {
        bail!("{} exists; pass --force to overwrite it", out.display());
    }
    Ok(())
}

fn curvature(device: Option<&str>, a: CurvatureArgs) -> Result<()> {
    let opts = options(&a);
    if a.report {
        let gpu = Arc::new(Gpu::new(device)?);
        let text = report::curvature_report(gpu, a.resolution, a.runs)?;
        print!("{text}");
        return Ok(());
    }
    let t_load = Instant::now();
    let (name, mesh) = match (&a.input, a.generate) {
        (_, Some(kind)) => generated(kind, a.resolution),
        (Some(path), None) => {
            let m = shapecue::mesh::load(path, &LoadOptions { weld: a.weld })?;
            (path.display().to_string(), m)
        }
        (None, None) => bail!("give an input mesh, --generate or --report"),
    };
    let load_ms = t_load.elapsed().as_secs_f64() * 1e3;
    for out in a.output.iter().chain(a.stats.iter()) {
        refuse_overwrite(out, a.input.as_deref(), a.force)?;
        if let Some(dir) = out.parent().filter(|d| !d.as_os_str().is_empty()) {
            std::fs::create_dir_all(dir).with_context(|| format!("creating {}", dir.display()))?;
        }
    }
    if a.output.is_none() && a.stats.is_none() {
        eprintln!("note: no --output or --stats given; computing and printing a summary only");
    }

    let t_all = Instant::now();
    let (field, counts, stats) = if a.cpu {
        let t = Instant::now();
        let (f, c) = shapecue::cpu::curvature::estimate(&mesh, &opts);
        let ms = t.elapsed().as_secs_f64() * 1e3;
        let stats = serde_json::json!({
            "device": "cpu reference (f64, single thread)",
            "wall_ms": ms,
        });
        (f, c, stats)
    } else {
        let gpu = Arc::new(Gpu::new(device)?);
        let info = gpu.info.clone();
        let mut est = CurvatureEstimator::new(gpu, mesh.n_vertices(), &mesh.faces, opts)
            .with_context(|| format!("setting up curvature for {name}"))?;
        let topo_ms = est.topology_ms();
        est.set_positions(&mesh.positions)?;
        let timing = est.run()?;
        let f = est.read()?;
        let c = est.counts()?;
        let stats = serde_json::json!({
            "device": info,
            "topology_ms": topo_ms,
            "passes": timing.passes,
            "kernel_ms": timing.kernel_ms,
            "run_wall_ms": timing.wall_ms,
            "device_bytes": est.device_bytes(),
            "device_bytes_per_vertex": est.device_bytes() as f64 / mesh.n_vertices() as f64,
        });
        (f, c, stats)
    };
    let total_ms = t_all.elapsed().as_secs_f64() * 1e3;
    if !field.all_finite() {
        bail!("internal error: non-finite output (please report with the input mesh)");
    }

    let (k1min, k1max) = minmax(&field.k1);
    let (k2min, k2max) = minmax(&field.k2);
    println!(
        "{name}: {} vertices, {} faces; k1 in [{k1min:.4}, {k1max:.4}], k2 in [{k2min:.4}, {k2max:.4}]; \
         {} degenerate faces skipped, {} vertices without curvature; {total_ms:.1} ms",
        mesh.n_vertices(),
        mesh.n_faces(),
        counts.degenerate_faces,
        counts.vertices_without_curvature
    );
    if let Some(out) = &a.output {
        shapecue::export::ply::write_ply(out, &mesh, Some(&field))?;
        println!("wrote {}", out.display());
    }
    if let Some(path) = &a.stats {
        let mut s = stats;
        s["input"] = serde_json::json!(name);
        s["vertices"] = serde_json::json!(mesh.n_vertices());
        s["faces"] = serde_json::json!(mesh.n_faces());
        s["options"] = serde_json::to_value(opts)?;
        s["counts"] = serde_json::to_value(counts)?;
        s["load_ms"] = serde_json::json!(load_ms);
        s["total_wall_ms"] = serde_json::json!(total_ms);
        std::fs::write(path, serde_json::to_string_pretty(&s)? + "\n")
            .with_context(|| format!("writing {}", path.display()))?;
        println!("wrote {}", path.display());
    }
    Ok(())
}

fn minmax(v: &[f64]) -> (f64, f64) {
    v.iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &x| {
            (a.min(x), b.max(x))
        })
}

fn isosurface(device: Option<&str>, a: IsoArgs) -> Result<()> {
    use shapecue::cpu::vertex_fusion::Fusion;
    use shapecue::stages::marching_cubes::{self as mcs, Isosurfacer};
    use shapecue::volume::{self, RawSpec, ScalarType};
    let fusion = match a.fusion {
        FusionArg::Hash => Fusion::Hash,
        FusionArg::Edge => Fusion::Edge,
        FusionArg::None => Fusion::None,
    };
    if a.report {
        let gpu = Arc::new(Gpu::new(device)?);
        print!(
            "{}",
            report::isosurface_report(gpu, a.max_resolution, a.runs)?
        );
        return Ok(());
    }
    let t_load = Instant::now();
    let (name, vol) = match (&a.input, &a.sdf) {
        (_, Some(kind)) => (
            format!("{kind} SDF {}³", a.resolution),
            volume::sdf::sdf_by_name(kind, a.resolution)?,
        ),
        (Some(path), None) => {
            let raw = match (&a.dims, &a.scalar) {
                (Some(d), Some(t)) => {
                    if d.len() != 3 {
                        bail!("--dims needs three values X,Y,Z, got {}", d.len());
                    }
                    let scalar: ScalarType = t.parse()?;
                    let mut spec = RawSpec::new([d[0], d[1], d[2]], scalar);
                    spec.big_endian = a.big_endian;
                    spec.header_bytes = a.header_bytes;
                    if let Some(sp) = &a.spacing {
                        if sp.len() != 3 {
                            bail!("--spacing needs three values, got {}", sp.len());
                        }
                        spec.spacing = [sp[0], sp[1], sp[2]];
                    }
                    Some(spec)
                }
                (None, None) => None,
                _ => bail!("raw input needs both --dims and --type"),
            };
            (
                path.display().to_string(),
                volume::load(path, raw.as_ref())?,
            )
        }
        (None, None) => bail!("give an input volume, --sdf or --report"),
    };
    let load_ms = t_load.elapsed().as_secs_f64() * 1e3;
    let iso = match (a.iso, &a.sdf) {
        (Some(v), _) => v,
        (None, Some(_)) => 0.0,
        (None, None) => bail!("give --iso (the volume's values span {:?})", vol.range()),
    };
    for out in a.output.iter().chain(a.stats.iter()) {
        refuse_overwrite(out, a.input.as_deref(), a.force)?;
        if let Some(dir) = out.parent().filter(|d| !d.as_os_str().is_empty()) {
            std::fs::create_dir_all(dir).with_context(|| format!("creating {}", dir.display()))?;
        }
    }
    let gpu = Arc::new(Gpu::new(device)?);
    let info = gpu.info.clone();
    let t_up = Instant::now();
    let mut ex = Isosurfacer::new(gpu, &vol).with_context(|| format!("uploading {name}"))?;
    let upload_ms = t_up.elapsed().as_secs_f64() * 1e3;
    let st = ex.extract(iso, fusion)?;
    let mut curv_stats = serde_json::Value::Null;
    let field = if a.curvature {
        let opts = CurvatureOptions {
            accumulate: Accumulate::Atomic,
            precision: match a.precision {
                PrecArg::F32 => Precision::F32,
                PrecArg::F64 => Precision::F64,
            },
            compat: Compat::Exact,
            dcurv: !a.no_dcurv,
        };
        let normals = match a.curvature_normals {
            NormalsArg::Gradient => mcs::IsoNormals::Gradient,
            NormalsArg::Mesh => mcs::IsoNormals::Mesh,
        };
        let (est, timing) = mcs::curvature(&ex, opts, normals)?;
        let f = est.read()?;
        if !f.all_finite() {
            bail!("internal error: non-finite curvature (please report with the input)");
        }
        curv_stats = serde_json::json!({
            "options": opts,
            "normals": normals,
            "passes": timing.passes,
            "kernel_ms": timing.kernel_ms,
            "run_wall_ms": timing.wall_ms,
            "counts": est.counts()?,
            "device_bytes": est.device_bytes(),
        });
        Some(f)
    } else {
        None
    };
    let (ipos, _) = ex.read_index_space()?;
    let mesh = ex.read()?;
    let q = shapecue::mesh::quality(&mesh.positions, &mesh.faces);
    println!(
        "{name}: iso {iso}, fusion {}: {} vertices, {} faces ({} soup vertices, {} degenerate \
         triangles dropped); extraction {:.1} ms kernels, {:.1} ms wall",
        fusion.name(),
        st.vertices,
        st.faces,
        st.soup_vertices,
        st.degenerate_dropped,
        st.kernel_ms,
        st.wall_ms
    );
    if let Some(out) = &a.output {
        let normals = a
            .normals
            .then(|| shapecue::cpu::marching_cubes::gradient_normals(&vol, &ipos));
        match (&field, normals) {
            (Some(f), n) => {
                let mut f = f.clone();
                if let Some(n) = n {
                    f.normals = n;
                }
                shapecue::export::ply::write_ply(out, &mesh, Some(&f))?;
            }
            (None, Some(n)) => shapecue::export::ply::write_ply_with_normals(out, &mesh, &n)?,
            (None, None) => shapecue::export::ply::write_ply(out, &mesh, None)?,
        }
        println!("wrote {}", out.display());
    }
    if let Some(path) = &a.stats {
        let s = serde_json::json!({
            "input": name,
            "device": info,
            "dims": vol.dims,
            "spacing": vol.spacing,
            "origin": vol.origin,
            "load_ms": load_ms,
            "upload_ms": upload_ms,
            "extraction": st,
            "quality": q,
            "curvature": curv_stats,
        });
        std::fs::write(path, serde_json::to_string_pretty(&s)? + "\n")
            .with_context(|| format!("writing {}", path.display()))?;
        println!("wrote {}", path.display());
    }
    Ok(())
}
