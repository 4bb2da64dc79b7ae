//! The `shapecue` command line, thin (ripgrep's habit): each command in
//! `cli/` parses its arguments, calls the library's front door
//! (`shapecue::curvature`, ...), writes the outputs and prints a summary.
//! Exit codes come from the library's error type, here and nowhere else.

mod cli;

use clap::{Parser, Subcommand};

#[global_allocator]
static ALLOC: cli::alloc::HugeBlocks = cli::alloc::HugeBlocks;

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
    Curvature(cli::curvature::CurvatureArgs),
    /// Build the curvature kernels for the device once and keep them in
    /// shapecue's kernel cache, so that later commands load them instead of
    /// compiling (run it after installing, or after a driver update; on PoCL
    /// it takes seconds per variant).
    BuildKernels(cli::kernels::KernelsArgs),
    /// Isosurface of a volume (marching cubes with vertex fusion on the
    /// device), optionally with curvature computed on the device right after.
    Isosurface(cli::isosurface::IsoArgs),
    /// Object-space feature edges with caps (House & Li): renders the
    /// mesh, then contour, crease and boundary/marked edges as thick quads with
    /// caps, to PNG (and SVG). Exit code 3: `--interop on` without a shared
    /// route (CL-GL sharing or external memory; PoCL has neither); 1: any other error.
    Edges(cli::edges::EdgesArgs),
    /// Line drawings with every line family of rtsc (Rusinkiewicz and
    /// DeCarlo): occluding and suggestive contours, ridges and valleys
    /// (Ohtake et al.), apparent ridges (Judd et al.), suggestive and
    /// principal highlights, isophotes, K = 0, H = 0, D_w κr = 0 and
    /// boundaries, to PNG or SVG (a group per family).
    Lines(cli::lines::LinesArgs),
    /// Render scene files (TOML): only the passes the scene's cues need run;
    /// images (PNG, SVG) and a JSON report of the passes that ran go to the
    /// scene's output folder. See `scenes/` and the README.
    Render(cli::render::RenderArgs),
    /// Curvature-directed strokes on a signed distance field (Interrante-style
    /// strokes along the first principal direction, curvature from the
    /// field's Hessian after Kindlmann et al. 2003): a volume, a procedural
    /// field or a mesh turned into a distance field, to PNG (and SVG, PLY).
    Strokes(cli::strokes::StrokesArgs),
    /// Measurements as Markdown tables (with --json numbers and --plot SVG
    /// charts), each headed by the date, the device and the command:
    /// curvature, isosurface, strokes, pipeline, caps, memory.
    Report(cli::report::ReportArgs),
    /// Open a window on a scene file or an input (mesh, glTF skin, LBS set,
    /// flipbook, volume): orbit, pan and zoom; every cue as a switch;
    /// sliders; animation; the passes each frame ran and their time; PNG and
    /// SVG screenshots; `--script` for reproducible figures. Exit code 4: no
    /// display (or no OpenGL for a window); 1: any other error.
    View(cli::view::ViewArgs),
}

fn main() {
    shapecue::export::output::install_interrupt_cleanup(
        "; a render's report is written when its scenes finish, so an interrupted render has \
         none; shapecue lines --out continues an interrupted run with --resume",
    );
    let cli = Cli::try_parse().unwrap_or_else(|e| cli::report::parse_error(e));
    let device = cli.device.as_deref();
    let result = match cli.cmd {
        Cmd::Devices { json } => cli::devices::run(device, json),
        Cmd::Curvature(a) => cli::curvature::run(device, a),
        Cmd::BuildKernels(a) => cli::kernels::run(device, a),
        Cmd::Isosurface(a) => cli::isosurface::run(device, a),
        Cmd::Edges(a) => cli::edges::run(device, a),
        Cmd::Lines(a) => cli::lines::run(device, a),
        Cmd::Render(a) => cli::render::run(device, a),
        Cmd::Strokes(a) => cli::strokes::run(device, a),
        Cmd::Report(a) => cli::report::run(device, a),
        Cmd::View(a) => cli::view::run(device, a),
    };
    // An interrupt that arrived while the last output was being finished:
    // the handler is exiting with 130, and so does the command.
    if shapecue::export::output::interrupted() {
        std::process::exit(130);
    }
    if let Err(e) = result {
        std::process::exit(cli::fail(&e));
    }
}
