//! `shapecue view INPUT | SCENE.toml`: a window that shows a mesh, an
//! animation or a volume with every cue as a switch, sliders for the
//! thresholds, widths and iso value, and the passes each frame ran.
//!
//! Files: `probe.rs` (frames and bounds of the input), `camera.rs` (orbit,
//! pan, zoom), `state.rs` (cues, sliders, the scene of a request),
//! `engine.rs` (the compute thread: the scene executor and the headless
//! renderer), `script.rs` (`--script`), `app.rs` (controls, keys, script
//! runner), `window.rs` (winit, glutin, egui). Window crates stay in this
//! folder: the library and its renderer know no window.

mod app;
mod camera;
mod engine;
mod probe;
mod script;
mod state;
mod window;

use anyhow::{Context, Result};
use clap::Args;
use shapecue::scene::file::Scene;
use std::path::{Path, PathBuf};

/// The exit code of `shapecue view` where no window can be opened (no
/// display, or no OpenGL for a window).
pub const NO_DISPLAY: i32 = 4;

/// No window can be opened: no display, or no OpenGL context for a window.
#[derive(Debug, thiserror::Error)]
#[error("cannot open a window: {0}")]
pub struct NoDisplay(pub String);

/// The arguments of `shapecue view`.
#[derive(Args)]
pub struct ViewArgs {
    /// A scene file (.toml), or an input as scenes take it: a mesh (OBJ,
    /// PLY, OFF), a glTF skin (.glb, .gltf), a libigl LBS set (its .obj
    /// beside a .tgf), a flipbook (a glob of frames in quotes) or a volume
    /// (NRRD, MetaImage, VTK, VTI, SLC).
    input: String,
    /// Run these camera moves, cue switches, slider sets, frame steps and
    /// screenshots, then close the window (see docs/viewer.md).
    #[arg(long)]
    script: Option<PathBuf>,
    /// Image size, WIDTHxHEIGHT (default: the scene's, else 800x600).
    #[arg(long)]
    size: Option<String>,
    /// Isovalue of a volume input (default: the middle of its values).
    #[arg(long, allow_hyphen_values = true)]
    iso: Option<f32>,
    /// Folder of the screenshots the S, V and C keys save (each under a new
    /// name, never over a file).
    #[arg(long, default_value = ".")]
    out: PathBuf,
    /// Let the script's screenshot, svg and capture commands replace files
    /// that exist (never the viewer's input).
    #[arg(long)]
    force: bool,
}

/// Extensions of volume files.
const VOLUMES: &[&str] = &["nrrd", "nhdr", "mha", "mhd", "vtk", "vti", "slc"];

fn quoted(p: &Path) -> String {
    toml::Value::String(p.display().to_string()).to_string()
}

/// The scene of `shapecue view INPUT`: the input with shading and contours,
/// one fitted camera.
fn scene_of_input(input: &str, iso: Option<f32>) -> Result<Scene> {
    let cwd = std::env::current_dir().context("cannot read the current folder")?;
    let path = cwd.join(input);
    let ext = path
        .extension()
        .map(|e| e.to_string_lossy().to_ascii_lowercase())
        .unwrap_or_default();
    let glob = input.contains(['*', '?', '[']);
    if !glob && !path.exists() {
        anyhow::bail!("{}: no such file", path.display());
    }
    let (line, volume) = if glob {
        (format!("flipbook = {}", quoted(&path)), false)
    } else if ext == "glb" || ext == "gltf" {
        (format!("gltf = {}", quoted(&path)), false)
    } else if ext == "obj" && path.with_extension("tgf").exists() {
        (format!("lbs = {}", quoted(&path)), false)
    } else if VOLUMES.contains(&ext.as_str()) {
        let iso = match iso {
            Some(v) => v,
            None => {
                let v = shapecue::volume::load(&path, None)?;
                let (lo, hi) = v.range().with_context(|| {
                    format!("{}: the volume has no finite value", path.display())
                })?;
                0.5 * (lo + hi)
            }
        };
        (format!("volume = {}\niso = {iso}", quoted(&path)), true)
    } else {
        (format!("mesh = {}", quoted(&path)), false)
    };
    if iso.is_some() && !volume {
        anyhow::bail!("--iso is for volume inputs; {input} is not a volume file");
    }
    let effects = if volume {
        "shading = {}\ncurvature_colors = {}\ncontours = {}"
    } else {
        "shading = {}\ncontours = {}"
    };
    let text = format!("[input]\n{line}\n\n[effects]\n{effects}\n\n[output]\nsize = [800, 600]\n");
    Ok(Scene::from_str(&cwd.join("view.toml"), &text)?)
}

/// Checks the files a script writes before the window opens, as every
/// command checks its outputs: none is an input of the viewer (the scene file
/// or any file its input is read from, even with `--force`), none is named
/// twice, and none exists unless `--force`.
fn check_script_outputs(
    script: &script::Script,
    scene: &Scene,
    probe: &probe::Probe,
    force: bool,
) -> Result<()> {
    let outputs = script.outputs();
    let mut inputs: Vec<&Path> = probe.files.iter().map(PathBuf::as_path).collect();
    if scene.path.exists() {
        inputs.push(scene.path.as_path());
    }
    inputs.push(script.path.as_path());
    let paths: Vec<&Path> = outputs.iter().map(|o| o.2).collect();
    super::check_outputs(inputs, paths, force).with_context(|| {
        format!(
            "{}: a file its screenshot, svg or capture commands would write",
            script.path.display()
        )
    })
}

/// Runs `shapecue view`.
pub fn run(device: Option<&str>, a: ViewArgs) -> Result<()> {
    if let Some(iso) = a.iso
        && !iso.is_finite()
    {
        anyhow::bail!("--iso {iso}: the isovalue must be a finite number");
    }
    let script = a.script.as_deref().map(script::Script::load).transpose()?;
    let mut scene = if a.input.ends_with(".toml") {
        if a.iso.is_some() {
            anyhow::bail!("--iso is for volume inputs; set a scene's iso in its [input]");
        }
        Scene::load(Path::new(&a.input))?
    } else {
        scene_of_input(&a.input, a.iso)?
    };
    if let Some(s) = &a.size {
        let (w, h) = super::size_arg(s)?;
        scene.size = [w, h];
    }
    let probe = probe::probe(&scene)?;
    if let Some(script) = &script {
        check_script_outputs(script, &scene, &probe, a.force)?;
    }
    let view = scene
        .views
        .first()
        .cloned()
        .with_context(|| format!("{}: the scene has no camera", scene.path.display()))?;
    let [w, h] = scene.size;
    let camera = camera::Orbit::new(view, probe.bounds, w as f32 / h as f32)?;
    let state = state::State::new(scene, probe.frames, camera, probe.values);
    let title = format!("shapecue view {}", a.input);
    let device = device.map(str::to_string);
    let out = a.out.clone();
    window::run(
        move |proxy| {
            let wake = Box::new(move || {
                let _ = proxy.send_event(window::Wake::Reply);
            });
            let engine =
                engine::Engine::start(device, wake).context("cannot start the compute thread")?;
            Ok(app::App::new(state, engine, script, out))
        },
        title,
        [w + 330, h.max(600) + 16],
    )
}
