//! `shapecue strokes`: curvature-directed strokes (Interrante's strokes on a
//! signed distance field, principal curvature from the Hessian after
//! Kindlmann et al. 2003) drawn over the shaded isosurface, to PNG, with the
//! strokes also as SVG outlines, a PLY of the strips and a stats JSON.
//!
//! Thin: parses, makes one front-door call ([`shapecue::strokes_on`]: the
//! strokes, the surface under them and the picture), writes with `export`,
//! prints one summary line (`shapecue report strokes` prints the
//! accuracy/time table against the analytic torus).

use anyhow::{Context, Result, bail};
use clap::Args;
use shapecue::api::{Gpu, VisibilityMethod};
use shapecue::export::output::{check_outputs, write_bytes_atomic};
use shapecue::spec::sdf_lines::{Inside, Sampling};
use shapecue::volume::{self, Volume};
use shapecue::{PictureOptions, Strokes, StrokesInput, StrokesOptions};
use std::path::{Path, PathBuf};
use std::sync::Arc;

/// Options of `shapecue strokes`.
#[derive(Args, Debug)]
pub struct StrokesArgs {
    /// Input: a volume (.nrrd/.nhdr, .mhd/.mha, .vtk, .vti, .slc, or raw
    /// data with --dims and --type) or a triangle mesh (.obj, .ply, .off).
    #[arg(required_unless_present = "sdf")]
    pub input: Option<PathBuf>,
    /// Use a procedural signed distance field instead: sphere, torus or gyroid.
    #[arg(long, conflicts_with = "input")]
    pub sdf: Option<String>,
    /// Grid points per axis of a procedural field; for a mesh input, samples
    /// along the mesh's longest axis of its signed distance field.
    #[arg(long, default_value_t = 128)]
    pub resolution: usize,
    /// Raw input: voxels per axis, e.g. 32,32,32.
    #[arg(long, value_delimiter = ',')]
    pub dims: Option<Vec<usize>>,
    /// Raw input: voxel type (u8, i8, u16, i16, u32, i32, f32, f64).
    #[arg(long = "type")]
    pub scalar: Option<String>,
    /// Raw input: world units per voxel step, e.g. 1,1,2.5.
    #[arg(long, value_delimiter = ',')]
    pub spacing: Option<Vec<f64>>,
    /// Raw input: big-endian data.
    #[arg(long)]
    pub big_endian: bool,
    /// Raw input: bytes to skip before the data.
    #[arg(long, default_value_t = 0)]
    pub header_bytes: usize,
    /// Iso value of the surface (default 0 for procedural fields; required
    /// for volume files).
    #[arg(long, allow_negative_numbers = true)]
    pub iso: Option<f32>,
    /// Which side of the iso value is inside the object: below (distance
    /// fields; the default for --sdf) or above (density data such as CT;
    /// the default for volume files). Normals point out, convex is positive.
    #[arg(long)]
    pub inside: Option<String>,
    /// Poisson-disk seed spacing r in world units (default: 1.5 × the
    /// Hessian sampling distance).
    #[arg(long, allow_negative_numbers = true)]
    pub seed_spacing: Option<f64>,
    /// Hessian sampling distance: auto (the candidate whose coefficient of
    /// variation of κ1 over the seeds is closest to 1) or a distance in
    /// world units.
    #[arg(long, default_value = "auto")]
    pub sampling: String,
    /// Output: .png (the shaded surface with its strokes) or .svg (the
    /// visible strokes' centre lines; with exact visibility no OpenGL is
    /// needed).
    #[arg(short, long, required = true)]
    pub output: Option<PathBuf>,
    /// How the hidden strokes of an -o .svg are found: exact (in object
    /// space, by rays towards the eye over a BVH of the isosurface) or
    /// depth (against the drawn picture's depth buffer).
    #[arg(long, value_parser = super::choice::<VisibilityMethod>(), default_value = "exact")]
    pub visibility: VisibilityMethod,
    /// Also write the strokes facing the eye as SVG (each a filled
    /// variable-width outline).
    #[arg(long)]
    pub svg: Option<PathBuf>,
    /// Also write the strips as a PLY triangle mesh (vertices on the surface).
    #[arg(long)]
    pub geometry: Option<PathBuf>,
    /// Write statistics (seeds before/after thinning, strokes, segments,
    /// the sampling sweep, per-step kernel ms) as JSON.
    #[arg(long)]
    pub stats: Option<PathBuf>,
    /// Eye position in world units, e.g. 0.5,-2,1.8 (default: a fitted view).
    #[arg(long, value_delimiter = ',', allow_negative_numbers = true)]
    pub eye: Option<Vec<f32>>,
    /// Image size, e.g. 800x800.
    #[arg(long, default_value = "800x800")]
    pub size: String,
    /// Strokes without the shaded surface: the surface is drawn in the
    /// background colour, so that it still hides the strokes behind it.
    #[arg(long)]
    pub no_surface: bool,
    /// Overwrite existing output files.
    #[arg(long)]
    pub force: bool,
}

/// Runs `shapecue strokes`.
///
/// # Errors
///
/// Bad arguments, an unreadable input, a mesh whose distance field cannot be
/// built (no faces, non-finite vertices), outputs that exist without `--force` or
/// are the input, and any library error.
pub fn run(device: Option<&str>, a: StrokesArgs) -> Result<()> {
    let (w, h) = super::size_arg(&a.size)?;
    let output = a.output.clone().expect("clap requires -o");
    let out_svg = super::png_or_svg("-o", &output, "the visible strokes")?;
    if out_svg && a.svg.is_some() {
        bail!(
            "-o {} is an SVG already: --svg adds the strokes facing the eye beside a PNG",
            output.display()
        );
    }
    let outputs: Vec<&Path> = [
        Some(&output),
        a.svg.as_ref(),
        a.geometry.as_ref(),
        a.stats.as_ref(),
    ]
    .into_iter()
    .flatten()
    .map(PathBuf::as_path)
    .collect();
    let (name, input) = load_input(&a, &outputs)?;
    let opts = strokes_options(&a, &input, (w, h))?;
    let gpu = Arc::new(Gpu::new(device)?);
    let front = match &input {
        Input::File(v) | Input::Sdf(v) => StrokesInput::Volume(v),
        Input::Mesh(m) => StrokesInput::Mesh(m, a.resolution),
    };
    let out = shapecue::strokes_on(&gpu, front, &opts).with_context(|| name.clone())?;
    if let Some(f) = &out.field {
        let st = &f.stats;
        super::out!(
            "{name}: signed distance field {}x{}x{} (spacing {:.4}), {:.1} ms kernels, {:.1} ms wall",
            st.dims[0],
            st.dims[1],
            st.dims[2],
            st.spacing,
            st.timing.kernel_ms,
            st.timing.wall_ms
        );
    }
    let picture = out.picture.as_ref().expect("a picture was asked for");
    match (&picture.frame, &picture.layers) {
        (_, Some(layers)) if out_svg => {
            shapecue::export::svg::write_svg_layers(&output, layers, w, h)?
        }
        (Some(frame), _) => frame.save_png(&output)?,
        _ => bail!("the picture drew no image for {}", output.display()),
    }
    print_summary(&name, &out, &output)?;
    if let Some(p) = &a.svg {
        let facing = picture.facing_strokes();
        shapecue::export::strokes::write_svg(p, &facing, &picture.camera, [w, h])?;
        super::out!(
            "wrote {} ({} strokes facing the eye)",
            p.display(),
            facing.len()
        );
    }
    if let Some(p) = &a.geometry {
        shapecue::export::strokes::write_ply(p, &out.strokes)?;
        super::out!("wrote {}", p.display());
    }
    if let Some(p) = &a.stats {
        write_stats(p, &name, &gpu, &out)?;
    }
    Ok(())
}

/// The front door's options from the arguments: iso value (required for a
/// volume file), inside, sampling, seed spacing and the `w`×`h` picture.
fn strokes_options(a: &StrokesArgs, input: &Input, (w, h): (u32, u32)) -> Result<StrokesOptions> {
    let procedural = !matches!(input, Input::File(_));
    let iso = match (a.iso, input) {
        (Some(v), _) => v,
        (None, Input::File(vol)) => bail!("give --iso ({})", span(vol)),
        (None, _) => 0.0,
    };
    if !iso.is_finite() {
        bail!("--iso must be a finite number within single precision (±3.4e38), got {iso}");
    }
    let inside: Inside = match &a.inside {
        Some(s) => s.parse()?,
        None if procedural => Inside::Below,
        None => Inside::Above,
    };
    let sampling = match a.sampling.as_str() {
        "auto" => Sampling::Auto(Vec::new()),
        s => match s.parse::<f64>() {
            Ok(d) if d.is_finite() && d > 0.0 => Sampling::Fixed(d),
            _ => bail!("--sampling {s:?}: expected auto or a positive distance in world units"),
        },
    };
    let eye = super::vec3_arg(&a.eye, "eye")?;
    Ok(StrokesOptions {
        iso,
        inside,
        sampling,
        spacing: a.seed_spacing,
        picture: Some(PictureOptions {
            shot: shapecue::Shot {
                size: [w, h],
                eye,
                ..PictureOptions::default().shot
            },
            surface: !a.no_surface,
            image: !super::has_extension(a.output.as_deref().unwrap_or(Path::new("")), "svg"),
            svg: super::has_extension(a.output.as_deref().unwrap_or(Path::new("")), "svg"),
            visibility: a.visibility,
        }),
    })
}

/// Prints the one summary line: samples, seeds, strokes, sampling distance
/// and kernel time, and the PNG written.
fn print_summary(name: &str, out: &Strokes, output: &Path) -> Result<()> {
    let st = &out.stats;
    let ms = st.timing.kernel_ms;
    super::out!(
        "{name}: {} surface samples → {} seeds after Poisson-disk thinning (r = {:.4}); {} strokes, \
         {} segments; sampling distance {:.4} ({}); kernels {ms:.1} ms; wrote {}",
        st.dense,
        st.seeds,
        st.params.map_or(0.0, |p| p.spacing),
        st.strokes,
        st.segments,
        st.params.map_or(0.0, |p| p.sampling),
        if st.sweep.is_empty() {
            "fixed"
        } else {
            "automatic: coefficient of variation of κ1 closest to 1"
        },
        output.display()
    );
    Ok(())
}

fn write_stats(p: &Path, name: &str, gpu: &Gpu, out: &Strokes) -> Result<()> {
    let st = &out.stats;
    let (dims, spacing, origin) = out.grid;
    let s = serde_json::json!({
        "input": name,
        "device": gpu.info,
        "dims": dims,
        "spacing": spacing,
        "origin": origin,
        "dense_samples": st.dense,
        "seeds": st.seeds,
        "strokes": st.strokes,
        "segments": st.segments,
        "strip_vertices": st.strip_vertices,
        "sampling_distance": st.params.map(|p| p.sampling),
        "params": st.params,
        "sweep": st.sweep,
        "k1_min": st.k1_min,
        "k1_max": st.k1_max,
        "kernel_ms": step_ms(&st.timing),
        "passes": out.timing,
        "wall_ms": st.timing.wall_ms,
    });
    write_bytes_atomic(p, (serde_json::to_string_pretty(&s)? + "\n").as_bytes())?;
    super::out!("wrote {}", p.display());
    Ok(())
}

/// The input: a volume file, a procedural field or a triangle mesh.
enum Input {
    File(Volume),
    Sdf(Volume),
    Mesh(shapecue::Mesh),
}

/// The range of a volume's values, in words.
fn span(v: &Volume) -> String {
    v.range()
        .map_or("the volume has no finite values".to_string(), |(lo, hi)| {
            format!("the values span {lo} to {hi}")
        })
}

/// Reads the input and checks the outputs against every file read (a
/// volume's detached data files included) before any conversion runs.
/// Returns (name, input).
fn load_input(a: &StrokesArgs, outputs: &[&Path]) -> Result<(String, Input)> {
    if let Some(kind) = &a.sdf {
        check_outputs(&[], outputs, a.force)?;
        let v = volume::sdf::sdf_by_name(kind, a.resolution)?;
        return Ok((format!("{kind} SDF {}³", a.resolution), Input::Sdf(v)));
    }
    let path = a.input.as_ref().expect("clap requires INPUT or --sdf");
    let ext = path
        .extension()
        .map(|e| e.to_string_lossy().to_ascii_lowercase())
        .unwrap_or_default();
    if matches!(ext.as_str(), "obj" | "ply" | "off") {
        // A triangle mesh becomes a signed distance field first (in the
        // library call).
        let mesh = shapecue::mesh::load(path, &Default::default())?;
        check_outputs(&[path.as_path()], outputs, a.force)?;
        return Ok((path.display().to_string(), Input::Mesh(mesh)));
    }
    let raw = super::raw_spec(
        a.dims.as_deref(),
        a.scalar.as_deref(),
        a.big_endian,
        a.header_bytes,
        a.spacing.as_deref(),
    )?;
    let (v, read) = volume::load_with_files(path, raw.as_ref())?;
    let inputs: Vec<&Path> = std::iter::once(path.as_path())
        .chain(read.iter().map(PathBuf::as_path))
        .collect();
    check_outputs(&inputs, outputs, a.force)?;
    Ok((path.display().to_string(), Input::File(v)))
}

/// Kernel ms per step under the names `--stats` has always used (`dense`,
/// `thin`, `gradient`, ..., `sweep`), and their `total`.
fn step_ms(t: &shapecue::spec::timing::Timing) -> serde_json::Value {
    use shapecue::spec::timing::Step;
    let names = [
        (Step::SdflDense, "dense"),
        (Step::SdflThin, "thin"),
        (Step::SdflGradient, "gradient"),
        (Step::SdflCurvature, "curvature"),
        (Step::SdflRange, "range"),
        (Step::SdflTrace, "trace"),
        (Step::SdflStrips, "strips"),
        (Step::SdflSweep, "sweep"),
    ];
    let mut m = serde_json::Map::new();
    for (step, name) in names {
        m.insert(name.into(), t.ms(&[step]).into());
    }
    m.insert("total".into(), t.kernel_ms.into());
    serde_json::Value::Object(m)
}
