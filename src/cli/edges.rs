//! `shapecue edges`: object-space feature edges with caps (House & Li),
//! drawn over the shaded mesh by one front-door call
//! ([`shapecue::feature_edges_picture_on`]) to PNG, with the visible edges
//! as SVG and JSON stats; `--runs` times more frames of the same view
//! ([`shapecue::report::frames`]). `shapecue report caps` and `shapecue
//! report memory` print the cap-quality and memory tables.

use super::{check_outputs, out, write_json};
use anyhow::{Result, bail};
use clap::Args;
use shapecue::EdgePictureOptions;
use shapecue::api::{Gpu, VisibilityMethod};
use shapecue::mesh::LoadOptions;
use shapecue::spec::edges::CapMode;
use std::path::PathBuf;
use std::sync::Arc;

/// The arguments of `shapecue edges`.
#[derive(Args)]
pub struct EdgesArgs {
    /// Input mesh (.obj, .ply, .off).
    mesh: PathBuf,
    /// Eye position, e.g. 5,5,5 (default: from direction 1,1,1 off the
    /// centre of the mesh, far enough that the mesh fills the view).
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
    /// Multisample antialiasing: 0 (off), 2, 4 or 8 samples per pixel. On
    /// Mesa's software rasteriser (llvmpipe) 4 samples cost about twice the
    /// time of none at 1024x1024.
    #[arg(long, default_value_t = 4)]
    msaa: u32,
    /// Output: .png (the shaded picture) or .svg (the visible edges as
    /// polylines; with exact visibility no OpenGL is needed).
    #[arg(short, long)]
    output: Option<PathBuf>,
    /// Also write the visible edges as SVG polylines beside a PNG.
    #[arg(long)]
    svg: Option<PathBuf>,
    /// How the SVG's hidden edges are found: exact (in object space, by
    /// rays towards the eye over a BVH of the mesh) or depth (against the
    /// drawn picture's depth buffer).
    #[arg(long, value_parser = super::choice::<VisibilityMethod>(), default_value = "exact")]
    visibility: VisibilityMethod,
    /// Write statistics (edge counts, timings, memory, interop path) as JSON.
    #[arg(long)]
    stats: Option<PathBuf>,
    /// Overwrite existing output files.
    #[arg(long)]
    force: bool,
    /// How the edge and cap buffers reach OpenGL: auto (CL-GL sharing where
    /// the device reports cl_khr_gl_sharing, else external memory where the
    /// device reports cl_khr_external_memory_opaque_fd, OpenGL
    /// GL_EXT_memory_object_fd and Vulkan VK_KHR_external_memory_fd, else
    /// a copy through the host), on (require a shared route: exit code 3
    /// without one), off (host path). --stats says which ran and why.
    #[arg(long, value_parser = super::choice::<shapecue::spec::edges::InteropMode>(), default_value = "auto")]
    interop: shapecue::spec::edges::InteropMode,
    /// After the first frame, this many more timed frames of the same view
    /// with the topology, device buffers, GL context and uploaded mesh kept
    /// (as a batch of views reuses them); --stats gives their medians
    /// (frame_median_ms, phases_median_ms). The image is the first frame's.
    #[arg(long)]
    runs: Option<usize>,
}

fn ms_since(t: std::time::Instant) -> f64 {
    t.elapsed().as_secs_f64() * 1e3
}

/// Runs `shapecue edges`.
pub fn run(device: Option<&str>, a: EdgesArgs) -> Result<()> {
    let Some(output) = &a.output else {
        bail!("give -o OUT.png (a picture) or -o OUT.svg (the visible edges)");
    };
    let out_svg = super::has_extension(output, "svg");
    // The options first: their messages name the flag at fault.
    let opts = picture_options(&a, out_svg)?;
    super::png_or_svg("-o", output, "the visible edges")?;
    if out_svg && a.svg.is_some() {
        bail!(
            "-o {} is an SVG already: --svg adds one beside a PNG",
            output.display()
        );
    }
    let [w, h] = opts.shot.size;
    if let Some(n) = a.runs {
        shapecue::spec::limits::check_count("--runs", n, 10_000)?;
    }
    let path = a.mesh.as_path();
    check_outputs(
        [path].into_iter().chain(a.marked.as_deref()),
        [Some(output), a.svg.as_ref(), a.stats.as_ref()]
            .into_iter()
            .flatten()
            .map(PathBuf::as_path),
        a.force,
    )?;
    let gpu = Arc::new(Gpu::new(device)?);
    let t_load = std::time::Instant::now();
    let mesh = Arc::new(shapecue::mesh::load(path, &LoadOptions::default())?);
    let load_ms = ms_since(t_load);
    let name = path.display().to_string();
    let d = shapecue::feature_edges_picture_on(&gpu, &mesh, &name, &opts)?;
    let t_png = std::time::Instant::now();
    match (&d.frame, &d.layers) {
        (_, Some(layers)) if out_svg => {
            shapecue::export::svg::write_svg_layers(output, layers, w, h)?
        }
        (Some(frame), _) => frame.save_png(output)?,
        _ => bail!("the picture drew no image for {}", output.display()),
    }
    // The output's write time: the PNG's, or the SVG's for -o OUT.svg.
    let (png_ms, mut svg_ms) = match out_svg {
        true => (0.0, ms_since(t_png)),
        false => (ms_since(t_png), 0.0),
    };
    print_summary(&name, &d, output)?;
    let runs = match a.runs {
        Some(n) => {
            let scene = shapecue::api::edges_scene(mesh, &name, &opts)?;
            let r = shapecue::report::frames::timed_frames(&gpu, &scene, n)?;
            out!(
                "{} timed frames: median {:.2} ms per frame, {:.3} ms kernels",
                r.runs,
                r.frame_median_ms,
                r.kernel_median_ms
            );
            Some(r)
        }
        None => None,
    };
    if let (Some(svg), Some(layers)) = (&a.svg, &d.layers) {
        let t_svg = std::time::Instant::now();
        shapecue::export::svg::write_svg_layers(svg, layers, w, h)?;
        svg_ms = ms_since(t_svg);
        let n: usize = layers.iter().map(|l| l.lines.len()).sum();
        out!("wrote {} ({n} polylines)", svg.display());
    }
    if let Some(sp) = &a.stats {
        let mut doc = stats(&name, &d, runs.as_ref());
        // The phases outside the library call: loading, PNG, SVG file.
        if let Some(ph) = doc.get_mut("phases_ms").and_then(|v| v.as_object_mut()) {
            ph.insert("load".into(), load_ms.into());
            ph.insert("png_write".into(), png_ms.into());
            ph.insert("svg_write".into(), svg_ms.into());
        }
        write_json(sp, &doc)?;
    }
    Ok(())
}

/// The picture's options from the arguments (checked here: the messages
/// name the flags).
fn picture_options(a: &EdgesArgs, out_svg: bool) -> Result<EdgePictureOptions> {
    // Parsed here rather than by clap's ValueEnum so that a bad name keeps
    // the library's message ("unknown cap mode ...") and exit code 1.
    let mode: CapMode = a.caps.parse()?;
    let (w, h) = super::size_arg(&a.size)?;
    // Checked before any table or drawing: the message names the flag.
    super::width_arg(a.width, (w, h), "edge")?;
    let shot = super::shot_arg([&a.eye, &a.target, &a.up], a.fov, a.ortho, [w, h])?;
    if shot.eye.is_none() && shot.target.is_some() {
        bail!("--target needs --eye (without both, the view is fitted around the mesh)");
    }
    Ok(EdgePictureOptions {
        shot,
        msaa: a.msaa,
        caps: mode,
        line_width: a.width,
        crease_deg: a.crease,
        depth_scale: a.depth_scale,
        half_contours: a.half_contours,
        marked: a.marked.clone(),
        image: !out_svg,
        svg: out_svg || a.svg.is_some(),
        visibility: a.visibility,
        interop: a.interop,
    })
}

/// The one line of counts and kernel time.
fn print_summary(name: &str, d: &shapecue::EdgePicture, output: &std::path::Path) -> Result<()> {
    let t = &d.counts;
    let [drawn, contour, crease, boundary] = d.kinds();
    out!(
        "{name}: {} edges ({} boundary, {} non-manifold, {} marked), {} cap pairs; drawn {drawn} \
         (in front of the near plane) of those detected as contour {contour}, crease {crease}, \
         boundary/marked {boundary}; kernels {:.3} ms; wrote {}",
        t.edges,
        t.boundary,
        t.non_manifold,
        t.marked,
        t.cap_pairs,
        d.timing.kernel_ms,
        output.display()
    );
    Ok(())
}

/// The statistics document of `--stats`: counts, timings, memory, the
/// interop route and what was offered; `input` names the mesh.
fn stats(
    input: &str,
    d: &shapecue::EdgePicture,
    runs: Option<&shapecue::report::frames::FrameRuns>,
) -> serde_json::Value {
    let t = &d.counts;
    let [drawn, contour, crease, boundary] = d.kinds();
    let phases: serde_json::Map<String, serde_json::Value> = (d.timing.phases.iter())
        .map(|p| (p.phase.to_string(), p.ms.into()))
        .collect();
    serde_json::json!({
        "input": input,
        "device": d.device,
        "vertices": d.vertices,
        "faces": d.faces,
        "edges": t.edges,
        "cap_pairs": t.cap_pairs,
        "boundary": t.boundary,
        "non_manifold": t.non_manifold,
        "marked": t.marked,
        "drawn": drawn,
        "contour": contour,
        "crease": crease,
        "boundary_or_marked": boundary,
        "caps": d.caps,
        // Adjacency caps drawn (the device holds only these).
        "drawn_caps": d.drawn_caps,
        "interop": d.interop,
        "interop_offer": d.offer,
        "timing": d.timing,
        "topology_ms": d.timing.phase_ms("edge_buffer") + d.timing.phase_ms("cap_buffer"),
        "frame_ms": d.timing.wall_ms,
        "phases_ms": phases,
        "memory_bits": d.memory,
        "svg_polylines": d.layers.as_ref().map_or(0, |l| l.iter().map(|l| l.lines.len()).sum()),
        "runs": runs.map(|r| r.runs),
        "frame_median_ms": runs.map(|r| r.frame_median_ms),
        "kernel_median_ms": runs.map(|r| r.kernel_median_ms),
        "phases_median_ms": runs.map(|r| &r.passes_median_ms),
        "gl_uploads": d.uploads,
    })
}
