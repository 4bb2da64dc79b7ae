//! The `shapecue` command line: thin; parses, calls the library, reports.

use anyhow::{Context, Result, bail};
use clap::{Args, Parser, Subcommand};
use shapecue::gpu::{Gpu, list_devices};
use shapecue::mesh::Generated;
use shapecue::mesh::{LoadOptions, Mesh};
use shapecue::report;
use shapecue::spec::curvature::{Accumulate, Compat, CurvatureOptions, Precision};
use shapecue::spec::marching_cubes::IsoNormals;
use shapecue::spec::vertex_fusion::Fusion;
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
    /// Object-space feature edges with caps (House & Li, seed 002): renders the
    /// mesh, then contour, crease and boundary/marked edges as thick quads with
    /// caps, to PNG (and SVG). Exit code 3: `--interop on` on a device without
    /// cl_khr_gl_sharing (such as PoCL); 1: any other error.
    Edges(EdgesArgs),
    /// Render scene files (TOML): only the passes the scene's cues need run;
    /// images (PNG, SVG) and a JSON report of the passes that ran go to the
    /// scene's output folder. See `scenes/` and the README.
    Render(RenderArgs),
}

#[derive(Args)]
struct RenderArgs {
    /// Scene files (with `--report`: glTF files to time the per-frame device
    /// pipeline on; default ../shared/data/animations/gltf/BrainStem.glb).
    #[arg(required_unless_present = "report")]
    scenes: Vec<PathBuf>,
    /// Print the per-frame device pipeline table (skin, curvature with dcurv,
    /// AO at each level with its error, contours and suggestive contours) of
    /// skinned glTF models, timed apart from rendering.
    #[arg(long)]
    report: bool,
    /// Frames of the first clip sampled by `--report`.
    #[arg(long, default_value_t = 30)]
    frames: usize,
    /// Timed runs per frame for `--report` (medians are printed).
    #[arg(long, default_value_t = 3)]
    runs: usize,
    /// Output folder (overrides each scene's `[output] dir`).
    #[arg(long)]
    out: Option<PathBuf>,
    /// Overwrite existing images and reports.
    #[arg(long)]
    force: bool,
    /// Print each scene's plan (passes, lifetimes, run counts) and exit
    /// without computing or writing anything.
    #[arg(long)]
    explain: bool,
}

#[derive(Args)]
struct EdgesArgs {
    /// Input mesh (.obj, .ply, .off).
    #[arg(required_unless_present_any = ["cap_quality", "memory_table"])]
    mesh: Option<PathBuf>,
    /// Eye position, e.g. 5,5,5.
    #[arg(
        long,
        value_delimiter = ',',
        num_args = 1,
        allow_negative_numbers = true
    )]
    eye: Option<Vec<f32>>,
    /// Point looked at (default: the centre of the mesh's bounding box).
    #[arg(long, value_delimiter = ',', allow_negative_numbers = true)]
    target: Option<Vec<f32>>,
    /// Up direction (default +Y, or +Z when looking along Y).
    #[arg(long, value_delimiter = ',', allow_negative_numbers = true)]
    up: Option<Vec<f32>>,
    /// Vertical field of view in degrees.
    #[arg(long, default_value_t = 40.0)]
    fov: f32,
    /// Orthographic projection (showing the height the perspective view shows at the target).
    #[arg(long)]
    ortho: bool,
    /// Caps filling the gaps between thick edges: none, mh (McGuire-Hughes
    /// half-caps from vertex normals) or adjacency (House & Li).
    #[arg(long, default_value = "adjacency")]
    caps: String,
    /// Edge width in pixels.
    #[arg(long, default_value_t = 4.0, allow_negative_numbers = true)]
    width: f32,
    /// Crease angle in degrees: edges whose face normals differ by more than
    /// this are creases (a cube's edges at 90°); 180 or more finds none.
    #[arg(long, default_value_t = 30.0, allow_negative_numbers = true)]
    crease: f32,
    /// Draw contour-only edges as half quads, outward from the silhouette.
    #[arg(long)]
    half_contours: bool,
    /// Depth-scaled width: width × max(1, K/w), w the clip-space depth.
    #[arg(long, allow_negative_numbers = true)]
    depth_scale: Option<f32>,
    /// Marked edges: a text file with one pair of 0-based vertex indices per line.
    #[arg(long)]
    marked: Option<PathBuf>,
    /// Image size, e.g. 800x600.
    #[arg(long, default_value = "800x600")]
    size: String,
    /// Output PNG.
    #[arg(short, long)]
    output: Option<PathBuf>,
    /// Also write the visible edges as SVG polylines.
    #[arg(long)]
    svg: Option<PathBuf>,
    /// Write statistics (edge counts, timings, memory, interop path) as JSON.
    #[arg(long)]
    stats: Option<PathBuf>,
    /// Overwrite existing output files.
    #[arg(long)]
    force: bool,
    /// CL-GL buffer sharing: auto (share when the device reports
    /// cl_khr_gl_sharing, else copy through the host), on (require it: exit
    /// code 3 without the extension), off (host path).
    #[arg(long, value_enum, default_value = "auto")]
    interop: shapecue::spec::edges::InteropMode,
    /// Print the cap-quality table (gap and extra pixels against the ideal
    /// round-joined stroke) for the standard meshes instead.
    #[arg(long)]
    cap_quality: bool,
    /// Print the memory table (bits per mesh for each cap variant) instead.
    #[arg(long)]
    memory_table: bool,
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
    fusion: Fusion,
    /// Write per-vertex normals from the volume gradient.
    #[arg(long)]
    normals: bool,
    /// Compute curvature on the device right after extraction (no host round trip).
    #[arg(long)]
    curvature: bool,
    /// Curvature precision.
    #[arg(long, value_enum, default_value = "f32")]
    precision: Precision,
    /// Vertex normals of the curvature passes: the volume gradient (accurate
    /// on marching-cubes meshes) or the mesh's own face normals (the paper's).
    #[arg(long, value_enum, default_value = "gradient")]
    curvature_normals: IsoNormals,
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

#[derive(Args)]
struct CurvatureArgs {
    /// Input mesh (.obj, .ply, .off).
    #[arg(required_unless_present_any = ["generate", "report"])]
    input: Option<PathBuf>,
    /// Use a generated mesh instead of a file.
    #[arg(long, value_enum, conflicts_with = "input")]
    generate: Option<Generated>,
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
    accumulate: Accumulate,
    /// Device precision.
    #[arg(long, value_enum, default_value = "f32")]
    precision: Precision,
    /// Exact least squares, or trimesh2 2.16 compatibility (its pivot quirk, |k1| ≥ |k2|).
    #[arg(long, value_enum, default_value = "exact")]
    compat: Compat,
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
    shapecue::export::output::install_interrupt_cleanup();
    if let Err(e) = run() {
        eprintln!("error: {e:#}");
        // The library's error decides the exit code (3: `--interop on`
        // without CL-GL sharing); everything else, CLI errors included, is 1.
        let code = e
            .downcast_ref::<shapecue::Error>()
            .map_or(1, shapecue::Error::exit_code);
        std::process::exit(code);
    }
}

fn run() -> Result<()> {
    let cli = Cli::parse();
    match cli.cmd {
        Cmd::Devices { json } => devices(json),
        Cmd::Curvature(a) => curvature(cli.device.as_deref(), a),
        Cmd::Isosurface(a) => isosurface(cli.device.as_deref(), a),
        Cmd::Edges(a) => edges(cli.device.as_deref(), a),
        Cmd::Render(a) => render(cli.device.as_deref(), a),
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
        accumulate: a.accumulate,
        precision: a.precision,
        compat: a.compat,
        dcurv: !a.no_dcurv,
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

/// Refuses each output that is the input or exists without `--force`, then
/// creates its parent folder.
fn prepare_outputs<'a>(
    outs: impl Iterator<Item = &'a PathBuf>,
    input: Option<&Path>,
    force: bool,
) -> Result<()> {
    for out in outs {
        refuse_overwrite(out, input, force)?;
        if let Some(dir) = out.parent().filter(|d| !d.as_os_str().is_empty()) {
            std::fs::create_dir_all(dir).with_context(|| format!("creating {}", dir.display()))?;
        }
    }
    Ok(())
}

/// Writes a stats document as pretty JSON and says so.
fn write_json(path: &Path, value: &serde_json::Value) -> Result<()> {
    shapecue::export::output::write_bytes_atomic(
        path,
        (serde_json::to_string_pretty(value)? + "\n").as_bytes(),
    )?;
    println!("wrote {}", path.display());
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
        (_, Some(kind)) => kind.mesh(a.resolution),
        (Some(path), None) => {
            let m = shapecue::mesh::load(path, &LoadOptions { weld: a.weld })?;
            (path.display().to_string(), m)
        }
        (None, None) => bail!("give an input mesh, --generate or --report"),
    };
    let load_ms = t_load.elapsed().as_secs_f64() * 1e3;
    prepare_outputs(
        a.output.iter().chain(a.stats.iter()),
        a.input.as_deref(),
        a.force,
    )?;
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
            "passes": curvature_passes(&timing),
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
        let written = shapecue::export::ply::write_ply(out, &mesh, Some(&field))?;
        note_double(out, &written);
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
        write_json(path, &s)?;
    }
    Ok(())
}

/// Says when a PLY file's properties were written as double.
fn note_double(out: &Path, w: &shapecue::export::ply::PlyWritten) {
    if let Some(why) = &w.double {
        eprintln!(
            "note: {} has double-precision vertex properties: {why}",
            out.display()
        );
    }
}

fn minmax(v: &[f64]) -> (f64, f64) {
    v.iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &x| {
            (a.min(x), b.max(x))
        })
}

fn isosurface(device: Option<&str>, a: IsoArgs) -> Result<()> {
    use shapecue::stages::marching_cubes::{self as mcs, Isosurfacer};
    use shapecue::volume::{self, RawSpec, ScalarType};
    let fusion = a.fusion;
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
    prepare_outputs(
        a.output.iter().chain(a.stats.iter()),
        a.input.as_deref(),
        a.force,
    )?;
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
            precision: a.precision,
            compat: Compat::Exact,
            dcurv: !a.no_dcurv,
        };
        let normals = a.curvature_normals;
        let (est, timing) = mcs::curvature(&ex, opts, normals)?;
        let f = est.read()?;
        if !f.all_finite() {
            bail!("internal error: non-finite curvature (please report with the input)");
        }
        curv_stats = serde_json::json!({
            "options": opts,
            "normals": normals,
            "passes": curvature_passes(&timing),
            "kernel_ms": timing.kernel_ms,
            "run_wall_ms": timing.wall_ms,
            "counts": est.counts()?,
            "device_bytes": est.device_bytes(),
        });
        Some(f)
    } else {
        None
    };
    let (ipos, faces) = ex.read_index_space()?;
    let mesh = ex.world_mesh(&ipos, faces);
    let q = shapecue::mesh::quality(&mesh.positions, &mesh.faces);
    println!(
        "{name}: iso {iso}, fusion {}: {} vertices, {} faces ({} soup vertices, {} degenerate \
         triangles dropped); extraction {:.1} ms kernels, {:.1} ms wall",
        fusion.name(),
        st.vertices,
        st.faces,
        st.soup_vertices,
        st.degenerate_dropped,
        st.timing.kernel_ms,
        st.timing.wall_ms
    );
    if let Some(out) = &a.output {
        let normals = a
            .normals
            .then(|| shapecue::cpu::marching_cubes::gradient_normals(&vol, &ipos));
        let written = match (&field, normals) {
            (Some(f), n) => {
                let mut f = f.clone();
                if let Some(n) = n {
                    f.normals = n;
                }
                shapecue::export::ply::write_ply(out, &mesh, Some(&f))?
            }
            (None, Some(n)) => shapecue::export::ply::write_ply_with_normals(out, &mesh, &n)?,
            (None, None) => shapecue::export::ply::write_ply(out, &mesh, None)?,
        };
        note_double(out, &written);
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
        write_json(path, &s)?;
    }
    Ok(())
}

fn vec3_arg(v: &Option<Vec<f32>>, what: &str) -> Result<Option<glam::Vec3>> {
    match v {
        None => Ok(None),
        Some(v) if v.len() == 3 && v.iter().all(|c| c.is_finite()) => {
            Ok(Some(glam::Vec3::new(v[0], v[1], v[2])))
        }
        Some(v) => bail!("--{what} needs three finite numbers X,Y,Z, got {v:?}"),
    }
}

fn size_arg(s: &str) -> Result<(u32, u32)> {
    let parsed = s
        .split_once(['x', 'X'])
        .and_then(|(w, h)| Some((w.trim().parse::<u32>().ok()?, h.trim().parse::<u32>().ok()?)));
    match parsed {
        Some((w, h)) if w > 0 && h > 0 && w <= 16384 && h <= 16384 => Ok((w, h)),
        _ => bail!("--size {s:?}: expected WIDTHxHEIGHT with both in 1..=16384, e.g. 800x600"),
    }
}

/// The meshes of seed 002's tables: generated cube, cylinder, cone and
/// icosphere, and the shared teapot and bunny when present; all unit-sized.
fn table_meshes() -> Vec<(String, Mesh)> {
    use shapecue::mesh as g;
    let mut v = vec![
        ("cube".to_string(), g::cube(1.0)),
        ("cylinder".to_string(), g::capped_cylinder(0.5, 1.0, 32)),
        ("cone".to_string(), g::cone(0.5, 1.0, 32)),
        ("icosphere".to_string(), g::icosphere(0.5, 3)),
    ];
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../shared/data/meshes");
    for (name, file) in [("teapot", "teapot.obj"), ("bunny", "stanford-bunny.obj")] {
        let p = dir.join(file);
        match shapecue::mesh::load(&p, &LoadOptions::default()) {
            Ok(m) => v.push((name.to_string(), m)),
            Err(e) => eprintln!("skipping {name}: {e}"),
        }
    }
    v.into_iter()
        .map(|(n, m)| (n, shapecue::mesh::unit_sized(&m)))
        .collect()
}

fn edges(device: Option<&str>, a: EdgesArgs) -> Result<()> {
    use shapecue::mesh::edges::EdgeTopology;
    use shapecue::render::edges::{EdgeDrawOptions, draw};
    use shapecue::spec::edges::{
        CapMode, EdgeParams, KIND_BOUNDARY, KIND_CONTOUR, KIND_CREASE, KIND_DRAWN,
        crease_from_degrees, decide_interop, memory_use,
    };
    // Parsed here rather than by clap's ValueEnum so that a bad name keeps
    // the library's message ("unknown cap mode ...") and exit code 1.
    let mode: CapMode = a.caps.parse()?;
    let (w, h) = size_arg(&a.size)?;
    if !(a.width.is_finite() && a.width > 0.0) {
        bail!(
            "--width {}: the edge width must be a positive number of pixels",
            a.width
        );
    }
    if a.memory_table {
        println!(
            "{:<10} {:>8} {:>9} {:>12} {:>12} {:>12}",
            "mesh", "edges", "caps", "none bits", "mh bits", "adj bits"
        );
        for (name, m) in table_meshes() {
            let t = EdgeTopology::new(&m, &[], &name)?;
            let bits = |c| {
                let u = memory_use(c, t.edges.len(), t.caps.len());
                u.edge_bits + u.cap_bits
            };
            println!(
                "{name:<10} {:>8} {:>9} {:>12} {:>12} {:>12}",
                t.edges.len(),
                t.caps.len(),
                bits(CapMode::None),
                bits(CapMode::Mh),
                bits(CapMode::Adjacency)
            );
        }
        println!(
            "(bits of the edge buffer, edge-out and kind, plus each variant's cap buffer and cap-out; 32-bit elements)"
        );
        return Ok(());
    }
    let gpu = Arc::new(Gpu::new(device)?);
    let interop = decide_interop(a.interop, gpu.info.gl_sharing, &gpu.info.name)?;
    if a.cap_quality {
        let crease = crease_from_degrees(a.crease)?;
        println!(
            "eye (5,5,5), unit-sized meshes at the origin, {w}x{h}, width {} px, crease {}°",
            a.width, a.crease
        );
        println!(
            "{:<10} {:<10} {:>8} {:>9} {:>8} {:>8}",
            "mesh", "caps", "ideal", "rendered", "gap", "extra"
        );
        for (name, m) in table_meshes() {
            let t = EdgeTopology::new(&m, &[], &name)?;
            let cam = shapecue::render::framed(
                shapecue::render::Placement::At(glam::Vec3::splat(5.0)),
                Some(glam::Vec3::ZERO),
                None,
                a.fov,
                a.ortho,
                m.bounds(),
                w as f32 / h as f32,
            )?;
            let mut p = EdgeParams::new(cam.view(w, h));
            p.line_width = a.width;
            p.crease_deg = crease;
            for q in shapecue::render::cap_quality::cap_quality(gpu.clone(), &m, &t, &p)? {
                println!(
                    "{name:<10} {:<10} {:>8} {:>9} {:>8} {:>8}",
                    q.mode.name(),
                    q.ideal,
                    q.rendered,
                    q.gap,
                    q.extra
                );
            }
        }
        return Ok(());
    }
    let path = a.mesh.as_deref().expect("clap requires MESH here");
    let Some(output) = &a.output else {
        bail!("give -o OUT.png (or --cap-quality / --memory-table)");
    };
    for out in [Some(output), a.svg.as_ref(), a.stats.as_ref()]
        .into_iter()
        .flatten()
    {
        refuse_overwrite(out, Some(path), a.force)?;
    }
    let mesh = shapecue::mesh::load(path, &LoadOptions::default())?;
    let Some(eye) = vec3_arg(&a.eye, "eye")? else {
        bail!("--eye X,Y,Z is required");
    };
    let opts = EdgeDrawOptions {
        eye,
        target: vec3_arg(&a.target, "target")?,
        up: vec3_arg(&a.up, "up")?,
        fov_deg: a.fov,
        ortho: a.ortho,
        width: w,
        height: h,
        caps: mode,
        line_width: a.width,
        crease_deg: a.crease,
        depth_scale: a.depth_scale,
        half_contours: a.half_contours,
        marked: a.marked.clone(),
        polylines: a.svg.is_some(),
    };
    let d = draw(gpu, &mesh, &path.display().to_string(), &opts)?;
    d.frame.save_png(output)?;
    let t = &d.topology;
    println!(
        "{}: {} edges ({} boundary, {} non-manifold, {} marked), {} cap pairs; drawn {} \
         (in front of the near plane) of those detected as contour {}, crease {}, \
         boundary/marked {}; kernels {:.3} ms; wrote {}",
        path.display(),
        t.edges.len(),
        t.boundary,
        t.non_manifold,
        t.marked,
        t.caps.len(),
        d.count(KIND_DRAWN),
        d.count(KIND_CONTOUR),
        d.count(KIND_CREASE),
        d.count(KIND_BOUNDARY),
        d.timing.kernel_ms,
        output.display()
    );
    if let (Some(svg), Some(lines)) = (&a.svg, &d.polylines) {
        shapecue::export::svg::write_svg(svg, lines, w, h, a.width)?;
        println!("wrote {} ({} polylines)", svg.display(), lines.len());
    }
    if let Some(sp) = &a.stats {
        write_json(sp, &d.stats(&path.display().to_string(), &interop))?;
    }
    Ok(())
}

fn render(device: Option<&str>, a: RenderArgs) -> Result<()> {
    use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
    use shapecue::scene::exec::{self, ExecOptions};
    use shapecue::scene::file::Scene;
    use std::io::IsTerminal;
    if a.report {
        let models = if a.scenes.is_empty() {
            vec![PathBuf::from(
                "../shared/data/animations/gltf/BrainStem.glb",
            )]
        } else {
            a.scenes.clone()
        };
        let gpu = Arc::new(Gpu::new(device)?);
        for m in &models {
            if !m.exists() {
                bail!(
                    "{}: not found (give the glTF files to time: `shapecue render --report MODEL.glb`)",
                    m.display()
                );
            }
            print!(
                "{}",
                report::pipeline_report(gpu.clone(), m, a.frames.max(1), a.runs.max(1))?
            );
        }
        return Ok(());
    }
    let opts = ExecOptions {
        out_dir: a.out.clone(),
        force: a.force,
        device: device.map(str::to_string),
    };
    // Check every scene before running any, so a typo in the last one does
    // not surface after minutes of rendering.
    let scenes: Vec<Scene> = a
        .scenes
        .iter()
        .map(|p| Scene::load(p))
        .collect::<shapecue::Result<_>>()?;
    for scene in &scenes {
        if a.explain {
            print!("{}", exec::explain(scene, &opts)?);
            continue;
        }
        let bar = ProgressBar::with_draw_target(None, ProgressDrawTarget::stderr());
        if !std::io::stderr().is_terminal() {
            bar.set_draw_target(ProgressDrawTarget::hidden());
        }
        bar.set_style(
            ProgressStyle::with_template(
                "{prefix} [{bar:30}] {pos}/{len} views {elapsed} ETA {eta}",
            )
            .expect("a valid template")
            .progress_chars("=> "),
        );
        bar.set_prefix(scene.name.clone());
        let r = exec::run(scene, &opts, &mut |done, total| {
            bar.set_length(total as u64);
            bar.set_position(done as u64);
        })?;
        bar.finish_and_clear();
        println!(
            "{}: {} frame(s) x {} view(s), {} vertices, {} faces on {}",
            r.scene,
            r.frames.len(),
            r.views,
            r.vertices,
            r.faces,
            r.device
        );
        println!(
            "  {:<20} {:<9} {:>6} {:>10} {:>10}  how",
            "pass", "lifetime", "runs", "total ms", "ms/run"
        );
        for p in &r.passes {
            println!(
                "  {:<20} {:<9} {:>6} {:>10.2} {:>10.3}  {} ({})",
                format!("{:?}", p.pass),
                format!("{:?}", p.lifetime),
                p.runs,
                p.ms,
                p.ms / p.runs.max(1) as f64,
                p.how,
                p.clock
            );
        }
        println!(
            "  per frame: pose passes {:.2} ms (median); per view: lines/edges {:.2} ms, render {:.1} ms; \
             segments: {} contour, {} suggestive; wall {:.0} ms",
            r.pose_ms_median,
            r.view_ms_median,
            r.render_ms_median,
            r.segments[0],
            r.segments[1],
            r.wall_ms
        );
        for n in &r.notes {
            println!("  note: {n}");
        }
        let dir = r
            .outputs
            .first()
            .and_then(|p| p.parent())
            .map(|p| p.display().to_string())
            .unwrap_or_default();
        println!(
            "  wrote {} file(s) to {dir} and the report",
            r.outputs.len()
        );
    }
    Ok(())
}

/// The curvature stats' `passes`: one `{pass, kernel_ms}` per curvature
/// step, named without the `curv_` prefix (`tensor`, `dcurv`).
fn curvature_passes(t: &shapecue::spec::timing::Timing) -> serde_json::Value {
    t.steps
        .iter()
        .map(|s| serde_json::json!({ "pass": s.step.name(), "kernel_ms": s.kernel_ms }))
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_generate_choice_is_a_library_mesh() {
        for k in Generated::ALL {
            let (desc, m) = k.mesh(500);
            assert!(!desc.is_empty() && m.n_faces() > 0);
        }
    }
}
