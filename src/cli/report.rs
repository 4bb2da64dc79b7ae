//! `shapecue report <topic>`: the measurement tables of [`shapecue::report`]
//! (accuracy against time of the curvature variants, the isosurfaces and
//! the strokes, and of the visibility methods of lines; the per-frame
//! pipeline and many-view line drawings; the edges' cap quality and memory).
//! Parses, calls the library's report, prints its Markdown and writes its
//! numbers (`--json`) and charts (`--plot`), atomically.

use super::check_outputs;
use anyhow::{Result, bail};
use clap::{Args, Subcommand};
use shapecue::api::Gpu;
use shapecue::report::{self, Report};
use std::path::{Path, PathBuf};
use std::sync::Arc;

/// The arguments of `shapecue report`.
#[derive(Args)]
#[command(subcommand_value_name = "TOPIC", subcommand_help_heading = "Topics")]
pub struct ReportArgs {
    #[command(subcommand)]
    topic: Topic,
}

/// The outputs every topic can write besides the printed Markdown.
#[derive(Args)]
struct Outputs {
    /// Write the numbers as JSON: each table's rows as objects with named,
    /// unit-suffixed fields, with the date, the device and the command.
    #[arg(long, value_name = "FILE")]
    json: Option<PathBuf>,
    /// Draw the numbers as an SVG plot (error against time on log axes,
    /// error against h with the h² slope, or bars).
    #[arg(long, value_name = "FILE.svg")]
    plot: Option<PathBuf>,
    /// Overwrite existing output files.
    #[arg(long)]
    force: bool,
}

#[derive(Subcommand)]
enum Topic {
    /// Every curvature variant on a generated torus: error against the
    /// analytic curvature and the f64 CPU reference, median kernel and wall
    /// ms; then the refinement sweep (error against edge length h).
    Curvature {
        /// Vertices of the torus (about). `--resolution` is its older
        /// name, kept as an alias.
        #[arg(long = "vertices", alias = "resolution", default_value_t = 40_000)]
        resolution: usize,
        /// Timed runs per variant (medians).
        #[arg(long, default_value_t = 7)]
        runs: usize,
        #[command(flatten)]
        out: Outputs,
    },
    /// Isosurfaces: extraction + fusion time and mesh quality of every
    /// fusion variant, then the resolution sweep of the sphere and torus
    /// fields (curvature error against the analytic values, and its time).
    Isosurface {
        /// Largest grid of the extraction table and the resolution sweep.
        #[arg(long, default_value_t = 512)]
        max_resolution: usize,
        /// Runs per measurement (medians).
        #[arg(long, default_value_t = 5)]
        runs: usize,
        #[command(flatten)]
        out: Outputs,
    },
    /// Curvature-directed strokes on the torus field: κ1 and direction
    /// error against the analytic torus per grid resolution and sampling
    /// distance, beside the kernel time.
    Strokes {
        /// Largest grid of the sweep (32, 64, 128, 256).
        #[arg(long, default_value_t = 256)]
        max_resolution: usize,
        #[command(flatten)]
        out: Outputs,
    },
    /// The per-frame device pipeline of skinned glTF models (skin,
    /// curvature with dcurv, AO at each level with its error, contours and
    /// suggestive contours), timed apart from rendering.
    Pipeline {
        /// glTF models (default: BrainStem.glb of the shared data).
        models: Vec<PathBuf>,
        /// Frames of the first clip.
        #[arg(long, default_value_t = 30)]
        frames: usize,
        /// Timed runs per frame (medians).
        #[arg(long, default_value_t = 3)]
        runs: usize,
        #[command(flatten)]
        out: Outputs,
    },
    /// Cap quality of the feature edges: gap and extra pixels of each cap
    /// variant against the ideal round-joined stroke, on the standard meshes.
    Caps {
        /// Image size, e.g. 800x600.
        #[arg(long, default_value = "800x600")]
        size: String,
        /// Edge width in pixels.
        #[arg(long, default_value_t = 4.0, allow_negative_numbers = true)]
        width: f32,
        /// Crease angle in degrees.
        #[arg(long, default_value_t = 30.0, allow_negative_numbers = true)]
        crease: f32,
        /// Vertical field of view in degrees.
        #[arg(long, default_value_t = 40.0)]
        fov: f32,
        /// Orthographic projection.
        #[arg(long)]
        ortho: bool,
        #[command(flatten)]
        out: Outputs,
    },
    /// Line drawings from many views in one run (`shapecue lines --views N
    /// --npz`): views per second with every line family and with contours
    /// and suggestive contours only, split into the per-pose and per-view
    /// parts, on the meshes given (default: the Stanford bunny of the shared
    /// data, else spot) and on a generated mesh of about a million faces.
    LinesBatch {
        /// Meshes to time.
        meshes: Vec<PathBuf>,
        /// Views of each mesh (Fibonacci cameras).
        #[arg(long, default_value_t = 32)]
        views: usize,
        /// Faces of the generated torus (0: none).
        #[arg(long, default_value_t = 1_000_000)]
        generated_faces: usize,
        /// Views of the generated mesh.
        #[arg(long, default_value_t = 4)]
        generated_views: usize,
        /// Image size, e.g. 800x600.
        #[arg(long, default_value = "800x600")]
        size: String,
        #[command(flatten)]
        out: Outputs,
    },
    /// Flicker of the line families on animations, with hysteresis over
    /// the frames off and on, beside a control where only the view moves:
    /// per family, the share of line length that pops between frames and
    /// that lives fewer than 3 frames, mapped to the rest pose (default:
    /// the elephant, BrainStem and Fox animations of the shared data, and
    /// the Fox bundled with the repository).
    Coherence {
        /// Scene files of skinned animations (their input, frames and first
        /// camera are used).
        scenes: Vec<PathBuf>,
        /// Image size, e.g. 640x480.
        #[arg(long, default_value = "640x480")]
        size: String,
        #[command(flatten)]
        out: Outputs,
    },
    /// Exact visibility of lines against its f64 reference, with the
    /// depth-buffer method beside it: per mesh and view, the share of line
    /// length each method agrees with the reference on, and its ms (default
    /// meshes: spot, and the Stanford bunny and BrainStem's middle frame of
    /// the shared data where present).
    Visibility(VisibilityArgs),
    /// Memory of the feature edges: bits per mesh of each cap variant, from
    /// the buffer sizes (no device needed).
    Memory {
        #[command(flatten)]
        out: Outputs,
    },
}

/// The arguments of `shapecue report visibility`.
#[derive(Args)]
struct VisibilityArgs {
    /// Meshes to measure (OBJ, PLY, OFF, STL; a glTF model: the middle
    /// frame of its first clip).
    meshes: Vec<PathBuf>,
    /// Every line family on the given meshes (else contours,
    /// suggestive contours, ridges, valleys and apparent ridges).
    #[arg(long)]
    every_family: bool,
    /// Timed runs per view (medians).
    #[arg(long, default_value_t = 5)]
    runs: usize,
    /// Image size the views frame (and the depth buffer's), e.g. 480x360.
    #[arg(long, default_value = "480x360")]
    size: String,
    /// Most ray–face tests of the f64 reference per view (it checks
    /// every k-th segment, k the least that keeps within them).
    #[arg(long, default_value_t = report::visibility::REFERENCE_TESTS)]
    reference_tests: f64,
    #[command(flatten)]
    out: Outputs,
}

/// Reports a command line clap refused and exits with clap's code; a topic
/// of `shapecue report` that does not exist gets the list of topics.
pub fn parse_error(e: clap::Error) -> ! {
    use clap::CommandFactory;
    use clap::error::ErrorKind;
    let unknown_topic =
        e.kind() == ErrorKind::InvalidSubcommand && std::env::args().skip(1).any(|a| a == "report");
    if !unknown_topic {
        e.exit();
    }
    let _ = e.print();
    let topics: Vec<String> = Topics::command()
        .get_subcommands()
        .map(|c| c.get_name().to_string())
        .collect();
    eprintln!(
        "The topics of `shapecue report` are: {}.",
        topics.join(", ")
    );
    std::process::exit(e.exit_code());
}

/// [`Topic`] as a command of its own, to list the topics' names.
#[derive(clap::Parser)]
struct Topics {
    #[command(subcommand)]
    _topic: Topic,
}

/// The command as typed, for the report's header (`shapecue report ...`),
/// arguments with spaces or quotes quoted.
fn command_line() -> String {
    let quote = |a: String| {
        if !a.is_empty()
            && a.chars()
                .all(|c| c.is_ascii_alphanumeric() || "-_./=,:@+".contains(c))
        {
            a
        } else {
            format!("'{}'", a.replace('\'', r"'\''"))
        }
    };
    std::iter::once("shapecue".to_string())
        .chain(std::env::args().skip(1).map(quote))
        .collect::<Vec<_>>()
        .join(" ")
}

fn runs(n: usize) -> Result<usize> {
    shapecue::spec::limits::check_count("--runs", n, 10_000)?;
    Ok(n)
}

/// Runs `shapecue report`.
pub fn run(device: Option<&str>, a: ReportArgs) -> Result<()> {
    let gpu = || -> Result<Arc<Gpu>> { Ok(Arc::new(Gpu::new(device)?)) };
    let (report, out) = match a.topic {
        Topic::Curvature {
            resolution,
            runs: n,
            out,
        } => (curvature(&gpu, resolution, n, &out)?, out),
        Topic::Isosurface {
            max_resolution,
            runs: n,
            out,
        } => (isosurface(&gpu, max_resolution, n, &out)?, out),
        Topic::Strokes {
            max_resolution,
            out,
        } => (strokes(&gpu, max_resolution, &out)?, out),
        Topic::Pipeline {
            models,
            frames,
            runs: n,
            out,
        } => (pipeline(&gpu, models, frames, n, &out)?, out),
        Topic::Caps {
            size,
            width,
            crease,
            fov,
            ortho,
            out,
        } => {
            let (w, h) = super::size_arg(&size)?;
            super::width_arg(width, (w, h), "edge")?;
            check(&[], &out)?;
            let o = report::caps::CapsReportOptions {
                size: (w, h),
                width,
                crease_deg: crease,
                fov_deg: fov,
                ortho,
            };
            (report::caps::report(&gpu()?, o)?, out)
        }
        Topic::LinesBatch {
            meshes,
            views,
            generated_faces,
            generated_views,
            size,
            out,
        } => {
            let o = report::lines_batch::LinesBatchOptions {
                meshes,
                views,
                generated_faces,
                generated_views,
                size: super::size_arg(&size).map(|(w, h)| [w, h])?,
            };
            (lines_batch(&gpu, o, &out)?, out)
        }
        Topic::Coherence { scenes, size, out } => {
            found(&scenes, "give the scene files of animations")?;
            let paths: Vec<&Path> = scenes.iter().map(PathBuf::as_path).collect();
            check(&paths, &out)?;
            let o = report::coherence::CoherenceOptions {
                scenes,
                size: Some(super::size_arg(&size).map(|(w, h)| [w, h])?),
            };
            (report::coherence::report(&gpu()?, &o)?, out)
        }
        Topic::Visibility(v) => visibility(&gpu, v)?,
        Topic::Memory { out } => {
            check(&[], &out)?;
            (report::memory::report()?, out)
        }
    };
    write(report.with_command(command_line()), &out)
}

/// `shapecue report curvature`: checks the runs, the torus and the
/// outputs, then measures.
fn curvature(
    gpu: &dyn Fn() -> Result<Arc<Gpu>>,
    resolution: usize,
    n: usize,
    out: &Outputs,
) -> Result<Report> {
    let o = report::curvature::CurvatureReportOptions {
        resolution,
        runs: runs(n)?,
    };
    shapecue::spec::limits::check_mesh_vertices("--vertices", resolution)?;
    check(&[], out)?;
    Ok(report::curvature::report(&gpu()?, o)?)
}

/// `shapecue report isosurface`: checks the runs, the largest grid and the
/// outputs, then measures.
fn isosurface(
    gpu: &dyn Fn() -> Result<Arc<Gpu>>,
    max_resolution: usize,
    n: usize,
    out: &Outputs,
) -> Result<Report> {
    let o = report::isosurface::IsosurfaceReportOptions {
        max_resolution,
        runs: runs(n)?,
    };
    shapecue::spec::limits::check_volume_resolution("--max-resolution", max_resolution)?;
    check(&[], out)?;
    Ok(report::isosurface::report(&gpu()?, o)?)
}

/// `shapecue report strokes`: checks the sweep's largest grid and the
/// outputs, then measures.
fn strokes(
    gpu: &dyn Fn() -> Result<Arc<Gpu>>,
    max_resolution: usize,
    out: &Outputs,
) -> Result<Report> {
    if !(32..=1024).contains(&max_resolution) {
        bail!(
            "--max-resolution {max_resolution}: the sweep's grids are 32³, 64³, 128³ and \
             256³; give 32 or more (at most 1024)"
        );
    }
    check(&[], out)?;
    let o = report::strokes::StrokesReportOptions { max_resolution };
    Ok(report::strokes::report(&gpu()?, o)?)
}

/// `shapecue report pipeline`: checks the models (the default one if none)
/// and the outputs, then measures.
fn pipeline(
    gpu: &dyn Fn() -> Result<Arc<Gpu>>,
    models: Vec<PathBuf>,
    frames: usize,
    n: usize,
    out: &Outputs,
) -> Result<Report> {
    let models = if models.is_empty() {
        vec![report::pipeline::default_model()]
    } else {
        models
    };
    if models.len() > report::pipeline::MAX_MODELS {
        bail!(
            "give at most {} glTF models per report",
            report::pipeline::MAX_MODELS
        );
    }
    found(
        &models,
        "give the glTF files to time: `shapecue report pipeline MODEL.glb`",
    )?;
    let paths: Vec<&Path> = models.iter().map(PathBuf::as_path).collect();
    check(&paths, out)?;
    let o = report::pipeline::PipelineReportOptions {
        frames: frames.max(1),
        runs: runs(n.max(1))?,
    };
    Ok(report::pipeline::report(&gpu()?, &paths, o)?)
}

/// `shapecue report lines-batch`: checks the views, the generated mesh,
/// the meshes and the outputs, then measures.
fn lines_batch(
    gpu: &dyn Fn() -> Result<Arc<Gpu>>,
    o: report::lines_batch::LinesBatchOptions,
    out: &Outputs,
) -> Result<Report> {
    for (n, flag) in [
        (o.views, "--views"),
        (o.generated_views, "--generated-views"),
    ] {
        if !(2..=shapecue::api::MAX_VIEWS).contains(&n) {
            bail!("{flag} {n}: give 2 to {} views", shapecue::api::MAX_VIEWS);
        }
    }
    if o.generated_faces > 0 {
        shapecue::spec::limits::check_mesh_vertices("--generated-faces", o.generated_faces)?;
    }
    found(&o.meshes, "give the meshes to time")?;
    let paths: Vec<&Path> = o.meshes.iter().map(PathBuf::as_path).collect();
    check(&paths, out)?;
    Ok(report::lines_batch::report(&gpu()?, &o)?)
}

/// `shapecue report visibility`: checks the size, the runs, the meshes,
/// the reference's budget and the outputs, then measures.
fn visibility(gpu: &dyn Fn() -> Result<Arc<Gpu>>, a: VisibilityArgs) -> Result<(Report, Outputs)> {
    if !(a.reference_tests.is_finite() && a.reference_tests >= 1.0) {
        bail!(
            "--reference-tests {}: give the most ray–face tests of the reference per view \
             (1 or more, e.g. 2e8)",
            a.reference_tests
        );
    }
    found(&a.meshes, "give the meshes to measure")?;
    let o = report::visibility::VisibilityReportOptions {
        size: super::size_arg(&a.size).map(|(w, h)| [w, h])?,
        runs: runs(a.runs.max(1))?,
        meshes: a.meshes,
        every_family: a.every_family,
        reference_tests: a.reference_tests,
    };
    let paths: Vec<&Path> = o.meshes.iter().map(PathBuf::as_path).collect();
    check(&paths, &a.out)?;
    Ok((report::visibility::report(&gpu()?, &o)?, a.out))
}

/// Refuses the first of `inputs` that does not exist, with `hint` (what to
/// give instead).
fn found(inputs: &[PathBuf], hint: &str) -> Result<()> {
    match inputs.iter().find(|m| !m.exists()) {
        Some(m) => bail!("{}: not found ({hint})", m.display()),
        None => Ok(()),
    }
}

/// Checks the outputs before any measuring: `--plot` must be `.svg`, and
/// neither may overwrite an input or (without `--force`) an existing file.
fn check(inputs: &[&Path], out: &Outputs) -> Result<()> {
    if let Some(p) = &out.plot {
        let svg = super::has_extension(p, "svg");
        if !svg {
            bail!(
                "--plot {}: plots are written as SVG; give a name ending in .svg",
                p.display()
            );
        }
    }
    check_outputs(
        inputs.iter().copied(),
        out.json.iter().chain(out.plot.iter()).map(PathBuf::as_path),
        out.force,
    )
}

/// Prints the Markdown and writes the JSON and the plot (saying so on
/// stderr: standard output is the Markdown page alone, to be saved as is).
fn write(report: Report, out: &Outputs) -> Result<()> {
    use shapecue::export::output::write_bytes_atomic;
    super::print_str(&report.markdown())?;
    if let Some(p) = &out.json {
        write_bytes_atomic(
            p,
            (serde_json::to_string_pretty(&report.json())? + "\n").as_bytes(),
        )?;
        eprintln!("wrote {}", p.display());
    }
    if let Some(p) = &out.plot {
        write_bytes_atomic(p, shapecue::report::plot::svg(&report)?.as_bytes())?;
        eprintln!("wrote {}", p.display());
    }
    Ok(())
}
