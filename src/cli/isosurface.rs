//! `shapecue isosurface`: the isosurface of a volume file or a procedural
//! signed distance field ([`shapecue::isosurface`]), optionally with its
//! curvature, written as PLY with JSON stats (`shapecue report isosurface`
//! prints the fusion and resolution tables).

use super::{check_outputs, out, write_json};
use anyhow::{Context, Result, bail};
use clap::Args;
use shapecue::api::Gpu;
use shapecue::spec::curvature::{AccumulateChoice, Compat, CurvatureOptions, Precision};
use shapecue::spec::marching_cubes::IsoNormals;
use shapecue::spec::vertex_fusion::Fusion;
use shapecue::volume;
use shapecue::{Inside, IsoOptions};
use std::path::{Path, PathBuf};
use std::sync::Arc;
use std::time::Instant;

/// The arguments of `shapecue isosurface`.
#[derive(Args)]
pub struct IsoArgs {
    /// Input volume: .nrrd/.nhdr, .mhd/.mha, .vtk (STRUCTURED_POINTS), .vti, or
    /// raw data with --dims and --type.
    #[arg(required_unless_present = "sdf")]
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
    /// Which side of the iso value the object is on, so that faces and
    /// gradient normals point out and convex parts have positive curvature
    /// (default: above for volume files such as CT or MRI densities, below
    /// for the procedural signed distance fields).
    #[arg(long, value_parser = super::choice::<Inside>())]
    inside: Option<Inside>,
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
    /// How triangles share vertices: direct (each vertex made once by its
    /// voxel edge and numbered by a scan, as Flying Edges does; exact and
    /// fastest), edge (a triangle soup fused by exact voxel-edge keys), hash
    /// (the soup fused by Griffin et al.'s position hash + radix sort), none
    /// (the triangle soup).
    #[arg(long, value_parser = super::choice::<Fusion>(), default_value = "direct")]
    fusion: Fusion,
    /// Write per-vertex normals from the volume gradient.
    #[arg(long)]
    normals: bool,
    /// Compute curvature on the device right after extraction (no host round trip).
    #[arg(long)]
    curvature: bool,
    /// Curvature precision.
    #[arg(long, value_parser = super::choice::<Precision>(), default_value = "f32")]
    precision: Precision,
    /// Curvature's one-ring accumulation, as for `shapecue curvature`
    /// (default: gather, bitwise reproducible).
    #[arg(long, value_parser = super::choice::<AccumulateChoice>(), default_value = "auto")]
    accumulate: AccumulateChoice,
    /// Curvature's least squares: exact, or trimesh2 2.16's.
    #[arg(long, value_parser = super::choice::<Compat>(), default_value = "exact")]
    compat: Compat,
    /// Vertex normals of the curvature passes: the volume gradient (accurate
    /// on marching-cubes meshes) or the mesh's own face normals (the paper's).
    #[arg(long, value_parser = super::choice::<IsoNormals>(), default_value = "gradient")]
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
    /// After the extraction whose results are written, this many more
    /// timed extractions (each a call of the library's isosurface, volume
    /// upload included; the times are the extraction's, with the volume on
    /// the device), whose medians --stats gives.
    #[arg(long)]
    runs: Option<usize>,
}

/// Runs `shapecue isosurface`.
pub fn run(device: Option<&str>, a: IsoArgs) -> Result<()> {
    if let Some(n) = a.runs {
        shapecue::spec::limits::check_count("--runs", n, 10_000)?;
    }
    let t_load = Instant::now();
    let (name, vol, read) = load_input(&a)?;
    let load_ms = t_load.elapsed().as_secs_f64() * 1e3;
    let iso = iso_value(&a, &vol)?;
    check_outputs(
        a.input
            .as_deref()
            .into_iter()
            .chain(read.iter().map(PathBuf::as_path)),
        a.output.iter().chain(a.stats.iter()).map(PathBuf::as_path),
        a.force,
    )?;
    let gpu = Arc::new(Gpu::new(device)?);
    let opts = iso_options(&a);
    let s = shapecue::isosurface_on(&gpu, &vol, iso, &opts)
        .with_context(|| format!("uploading {name}"))?;
    let runs = match a.runs {
        Some(n) => shapecue::report::metrics::isosurface_runs(&gpu, &vol, iso, &opts, n)?,
        None => Vec::new(),
    };
    let st = &s.stats;
    if st.faces == 0 {
        // As in scenes: an empty surface is an error, not an empty file.
        bail!(
            "{name}: the isosurface at iso {iso} is empty ({})",
            values_span(&vol)
        );
    }
    out!(
        "{name}: iso {iso}, fusion {}: {} vertices, {} faces ({} soup vertices, {} degenerate \
         triangles dropped); extraction {:.1} ms kernels, {:.1} ms wall",
        a.fusion.name(),
        st.vertices,
        st.faces,
        st.soup_vertices,
        st.degenerate_dropped,
        st.timing.kernel_ms,
        st.timing.wall_ms
    );
    if a.runs.is_some() {
        print_runs(&runs)?;
    }
    let t_write = Instant::now();
    if let Some(out) = &a.output {
        write_ply(out, &s)?;
        out!("wrote {}", out.display());
    }
    let write_ms = t_write.elapsed().as_secs_f64() * 1e3;
    if let Some(path) = &a.stats {
        let curv = curvature_stats(&a, &opts, &s);
        let mut stats = serde_json::json!({
            "input": name,
            "device": gpu.info,
            "dims": vol.dims,
            "spacing": vol.spacing,
            "origin": vol.origin,
            "load_ms": load_ms,
            "upload_ms": s.stats.timing.phase_ms("upload"),
            "extraction": st,
            "quality": shapecue::mesh::quality(&s.mesh.positions, &s.mesh.faces),
            "curvature": curv,
            "write_ms": write_ms,
        });
        if !runs.is_empty() {
            shapecue::report::metrics::runs_stats(&mut stats, &runs, st.timing.wall_ms);
        }
        write_json(path, &stats)?;
    }
    Ok(())
}

/// The PLY of an isosurface: with curvature (gradient normals replacing the
/// estimator's when `--normals` asked for them), with normals only, or bare.
fn write_ply(out: &Path, s: &shapecue::Isosurface) -> Result<()> {
    use shapecue::export::ply;
    let written = match (&s.curvature, &s.normals) {
        (Some(c), n) => {
            let mut f = c.field.clone();
            if let Some(n) = n {
                f.normals = n.clone();
            }
            ply::write_ply(out, &s.mesh, Some(&f))?
        }
        (None, Some(n)) => ply::write_ply_with_normals(out, &s.mesh, n)?,
        (None, None) => ply::write_ply(out, &s.mesh, None)?,
    };
    super::note_double(out, &written);
    Ok(())
}

/// The volume of the arguments (a file, with every file it was read from,
/// or a generated SDF) and its name for messages.
fn load_input(a: &IsoArgs) -> Result<(String, volume::Volume, Vec<PathBuf>)> {
    Ok(match (&a.input, &a.sdf) {
        (_, Some(kind)) => (
            format!("{kind} SDF {}³", a.resolution),
            {
                // Checked here first: the message names the flag.
                shapecue::spec::limits::check_volume_resolution("--resolution", a.resolution)?;
                volume::sdf::sdf_by_name(kind, a.resolution)?
            },
            Vec::new(),
        ),
        (Some(path), None) => {
            let raw = super::raw_spec(
                a.dims.as_deref(),
                a.scalar.as_deref(),
                a.big_endian,
                a.header_bytes,
                a.spacing.as_deref(),
            )?;
            let (vol, read) = volume::load_with_files(path, raw.as_ref())?;
            (path.display().to_string(), vol, read)
        }
        (None, None) => bail!("give an input volume or --sdf"),
    })
}

/// `--iso`, or 0 for an SDF; a volume file needs it given, finite.
fn iso_value(a: &IsoArgs, vol: &volume::Volume) -> Result<f32> {
    let iso = match (a.iso, &a.sdf) {
        (Some(v), _) => v,
        (None, Some(_)) => 0.0,
        (None, None) => match vol.range() {
            Some((lo, hi)) => bail!("give --iso (the volume's values span {lo} to {hi})"),
            None => bail!("give --iso (the volume has no finite values)"),
        },
    };
    if !iso.is_finite() {
        bail!("--iso must be a finite number within single precision (±3.4e38), got {iso}");
    }
    Ok(iso)
}

/// The extraction's options from the arguments.
fn iso_options(a: &IsoArgs) -> IsoOptions {
    let curvature = a.curvature.then_some(CurvatureOptions {
        accumulate: a.accumulate.resolve(),
        precision: a.precision,
        compat: a.compat,
        dcurv: !a.no_dcurv,
        lanes: shapecue::spec::curvature::Lanes::Auto,
    });
    IsoOptions {
        fusion: a.fusion,
        inside: a.inside.unwrap_or(if a.sdf.is_some() {
            Inside::Below
        } else {
            Inside::Above
        }),
        curvature,
        curvature_normals: a.curvature_normals,
        gradient_normals: a.normals && a.output.is_some(),
    }
}

/// The range of a volume's values, in words.
fn values_span(vol: &volume::Volume) -> String {
    vol.range()
        .map_or("no finite values".to_string(), |(lo, hi)| {
            format!("the values span {lo} to {hi}")
        })
}

/// The medians of the timed extractions (`--runs`).
fn print_runs(runs: &[shapecue::spec::timing::Timing]) -> Result<()> {
    let mut k: Vec<f64> = runs.iter().map(|t| t.kernel_ms).collect();
    let mut w: Vec<f64> = runs.iter().map(|t| t.wall_ms).collect();
    out!(
        "{} timed extractions: median {:.2} ms kernels, {:.2} ms wall",
        runs.len(),
        shapecue::report::metrics::median(&mut k),
        shapecue::report::metrics::median(&mut w)
    );
    Ok(())
}

/// The curvature part of `--stats` (null without `--curvature`).
fn curvature_stats(a: &IsoArgs, opts: &IsoOptions, s: &shapecue::Isosurface) -> serde_json::Value {
    s.curvature.as_ref().map_or(serde_json::Value::Null, |c| {
        serde_json::json!({
            "options": opts.curvature,
            "normals": a.curvature_normals,
            "passes": super::curvature::passes(&c.timing),
            "kernel_ms": c.timing.kernel_ms,
            "run_wall_ms": c.timing.wall_ms,
            "counts": c.counts,
            "device_bytes": c.device_bytes,
        })
    })
}
