//! The viewer's app: the state, the compute thread, the script and the
//! controls. `ui` draws the controls and the latest frame and turns mouse
//! and keys into state changes; `step` sends the state to the compute thread
//! when it changed, plays the animation, and runs the script.

use super::engine::{Done, Engine, Reply, Request};
use super::script::{Command, FrameMove, Script};
use super::state::State;
use anyhow::{Result, anyhow, bail};
use egui::{Key, PointerButton, Sense};
use std::path::{Path, PathBuf};
use std::time::Instant;

/// A script being run: its commands and the next one.
struct Running {
    script: Script,
    next: usize,
}

/// The app.
pub struct App {
    pub state: State,
    engine: Engine,
    script: Option<Running>,
    /// Folder of the screenshots the keys save.
    out: PathBuf,
    /// The last request sent, the last one answered (a frame or a failure),
    /// and whether the state changed since.
    sent: u64,
    answered: u64,
    dirty: bool,
    /// Ask the next request for the SVG (and where to copy it).
    svg_to: Option<PathBuf>,
    /// The latest frame, and whether its texture is up to date.
    shown: Option<Box<Done>>,
    fresh: bool,
    texture: Option<egui::TextureHandle>,
    /// The last error of the compute thread, and the request it failed.
    error: Option<String>,
    failed: Option<u64>,
    /// Frame times (ms, compute thread), for the summary.
    times: Vec<f64>,
    /// When the animation last moved on; the UI's last repaint.
    played: Instant,
    ui_frame: (Instant, f64),
    /// Where the next painted window goes (PNG).
    pub capture: Option<PathBuf>,
    /// Status line (what a key did).
    note: String,
    quit: bool,
}

impl App {
    /// The app of a state, on a started compute thread.
    pub fn new(state: State, engine: Engine, script: Option<Script>, out: PathBuf) -> App {
        App {
            state,
            engine,
            script: script.map(|script| Running { script, next: 0 }),
            out,
            sent: 0,
            answered: 0,
            dirty: true,
            svg_to: None,
            shown: None,
            fresh: false,
            texture: None,
            error: None,
            failed: None,
            times: Vec::new(),
            played: Instant::now(),
            ui_frame: (Instant::now(), 0.0),
            capture: None,
            note: String::new(),
            quit: false,
        }
    }

    /// Whether the event loop should repaint at once (a state not sent yet,
    /// a window capture asked for, a script that waits on no frame: one
    /// whose request was refused before it reached the compute thread, as
    /// with every cue switched off). Frames from the compute thread wake it
    /// by themselves, so it does not spin while one is drawn.
    pub fn wants_frames(&self) -> bool {
        self.dirty || self.capture.is_some() || (self.script.is_some() && !self.in_flight())
    }

    /// Whether a request is out that the compute thread has not answered.
    fn in_flight(&self) -> bool {
        self.answered < self.sent
    }

    /// How long to wait before the next animation step, while playing.
    pub fn play_period(&self) -> Option<std::time::Duration> {
        self.state
            .playing
            .then(|| std::time::Duration::from_secs_f32(1.0 / self.state.scene.fps.max(1.0)))
    }

    /// Whether the frame on screen is the one of the current state.
    fn current(&self) -> bool {
        !self.dirty && self.shown.as_ref().is_some_and(|d| d.id == self.sent)
    }

    /// Sends the state to the compute thread.
    fn send(&mut self, svg: bool) {
        if self.state.enabled().is_empty() {
            // Nothing to draw: no request (the planner would plan no pass);
            // the state counts as sent and failed at once, so that a script
            // waiting for its frame stops with this error.
            self.sent += 1;
            self.answered = self.sent;
            self.dirty = false;
            self.error = Some("no cue is switched on".into());
            self.failed = Some(self.sent);
            return;
        }
        self.sent += 1;
        self.engine.send(Request {
            id: self.sent,
            scene: self.state.request_scene(),
            svg,
        });
        self.dirty = false;
    }

    /// Takes the compute thread's replies.
    fn receive(&mut self) {
        while let Ok(r) = self.engine.rx.try_recv() {
            match r {
                Reply::Frame(d) => {
                    self.answered = self.answered.max(d.id);
                    self.times.push(d.wall_ms);
                    self.error = None;
                    self.failed = None;
                    if let (Some(svg), Some(to)) = (&d.svg, self.svg_to.as_ref()) {
                        self.note = match copy(svg, to) {
                            Ok(()) => format!("wrote {}", to.display()),
                            Err(e) => e.to_string(),
                        };
                        self.svg_to = None;
                    }
                    self.shown = Some(d);
                    self.fresh = true;
                }
                Reply::Failed(id, e) => {
                    self.answered = self.answered.max(id);
                    self.error = Some(e);
                    self.failed = Some(id);
                }
            }
        }
    }

    /// One turn of the loop after a repaint: replies in, requests out,
    /// animation and script on. `Ok(false)`: quit.
    pub fn step(&mut self) -> Result<bool> {
        self.receive();
        if self.state.playing
            && self.current()
            && self.played.elapsed().as_secs_f32() >= 1.0 / self.state.scene.fps.max(1.0)
        {
            self.state.step(1);
            self.played = Instant::now();
            self.dirty = true;
        }
        if self.script.is_some() {
            self.run_script()?;
        }
        if self.dirty {
            self.send(false);
        }
        Ok(!self.quit)
    }

    /// Runs script commands until one needs a frame that is not drawn yet.
    fn run_script(&mut self) -> Result<()> {
        loop {
            if self.capture.is_some() {
                // The next repaint saves the window first.
                return Ok(());
            }
            let Some(run) = self.script.as_mut() else {
                return Ok(());
            };
            let Some((line, cmd)) = run.script.commands.get(run.next).cloned() else {
                self.script = None;
                self.quit = true;
                return Ok(());
            };
            let at = format!("{} line {line}", run.script.path.display());
            if cmd.needs_frame() {
                // The state's own frame failed (not a stale one): stop here.
                if let Some(e) = &self.error
                    && !self.dirty
                    && self.failed == Some(self.sent)
                {
                    bail!("{at}: the frame failed: {e}");
                }
                let svg = matches!(cmd, Command::Svg(_));
                if self.dirty || (svg && self.svg_to.is_none() && !self.has_svg()) {
                    if let Command::Svg(p) = &cmd {
                        self.svg_to = Some(p.clone());
                    }
                    self.send(svg);
                    return Ok(());
                }
                if !self.current() || (svg && self.svg_to.is_some()) {
                    return Ok(());
                }
            }
            self.command(&cmd).map_err(|e| anyhow!("{at}: {e}"))?;
            if let Some(run) = self.script.as_mut() {
                run.next += 1;
            }
        }
    }

    /// Whether the frame on screen came with its SVG.
    fn has_svg(&self) -> bool {
        self.shown.as_ref().is_some_and(|d| d.svg.is_some())
    }

    /// Applies one command (a frame command once the frame is current).
    fn command(&mut self, cmd: &Command) -> Result<()> {
        let cam = &mut self.state.camera;
        match cmd {
            Command::Orbit(y, p) => cam.orbit(*y, *p),
            Command::Pan(x, y) => cam.pan(*x, *y),
            Command::Zoom(f) => cam.zoom(*f),
            Command::Reset => cam.reset(),
            Command::Cue(name, on) => self.state.set_cue(name, *on).map_err(|e| anyhow!(e))?,
            Command::Set(k, v) => self.state.set(k, v).map_err(|e| anyhow!(e))?,
            Command::Frame(FrameMove::By(d)) => self.state.step(*d),
            Command::Frame(FrameMove::To(f)) => {
                if *f >= self.state.frames.len() {
                    bail!(
                        "frame {f}: the scene has {} frame(s)",
                        self.state.frames.len()
                    );
                }
                self.state.frame = *f;
            }
            Command::Wait => {}
            Command::Capture(p) => self.capture = Some(p.clone()),
            Command::Svg(p) => println!("wrote {}", p.display()),
            Command::Screenshot(p) => {
                self.screenshot(p)?;
                println!("wrote {}", p.display());
            }
            Command::Passes => {
                let d = self
                    .shown
                    .as_ref()
                    .ok_or_else(|| anyhow!("no frame drawn"))?;
                let names: Vec<&str> = d.passes.iter().map(|p| p.pass.name()).collect();
                println!("passes: {}", names.join(" "));
                let times: Vec<String> = d
                    .passes
                    .iter()
                    .map(|p| format!("{} {:.1}", p.pass.name(), p.ms()))
                    .collect();
                println!("  ms: {}; frame {:.1}", times.join(", "), d.wall_ms);
            }
        }
        if !cmd.needs_frame() {
            self.dirty = true;
        }
        Ok(())
    }

    /// Saves the frame on screen as PNG.
    fn screenshot(&self, path: &Path) -> Result<()> {
        let d = self
            .shown
            .as_ref()
            .ok_or_else(|| anyhow!("no frame drawn yet"))?;
        let frame = shapecue::render::Frame {
            width: d.image.width(),
            height: d.image.height(),
            rgba: d.image.as_raw().clone(),
            depth: Vec::new(),
        };
        frame.save_png(path)?;
        Ok(())
    }

    /// The first free `shapecue-view-NNN.EXT` in the output folder.
    fn free_name(&self, ext: &str) -> PathBuf {
        (1..)
            .map(|i| self.out.join(format!("shapecue-view-{i:03}.{ext}")))
            .find(|p| !p.exists())
            .unwrap_or_else(|| self.out.join(format!("shapecue-view.{ext}")))
    }

    /// Prints the frame-time summary; the script's last error, if any.
    pub fn finish(&mut self) -> Result<()> {
        let mut t = self.times.clone();
        if !t.is_empty() {
            let med = shapecue::report::metrics::median(&mut t);
            println!(
                "view: {} frame(s) drawn; median frame time {med:.1} ms ({:.1} frames/s)",
                self.times.len(),
                1e3 / med.max(1e-9)
            );
        }
        Ok(())
    }

    /// Draws the controls and the frame; mouse and keys change the state.
    pub fn ui(&mut self, ui: &mut egui::Ui) {
        let now = Instant::now();
        self.ui_frame = (now, now.duration_since(self.ui_frame.0).as_secs_f64() * 1e3);
        self.receive();
        let ctx = ui.ctx().clone();
        if self.fresh
            && let Some(d) = &self.shown
        {
            let size = [d.image.width() as usize, d.image.height() as usize];
            let img = egui::ColorImage::from_rgba_unmultiplied(size, d.image.as_raw());
            match &mut self.texture {
                Some(t) => t.set(img, egui::TextureOptions::LINEAR),
                None => {
                    self.texture =
                        Some(ctx.load_texture("frame", img, egui::TextureOptions::LINEAR))
                }
            }
            self.fresh = false;
        }
        // The frame time and any error in a line of their own under
        // everything, where a small window still shows them whole.
        egui::Panel::bottom("status").show(ui, |ui| self.timings(ui));
        egui::Panel::left("controls")
            .resizable(false)
            .default_size(260.0)
            .show(ui, |ui| {
                egui::ScrollArea::vertical().show(ui, |ui| self.controls(ui));
            });
        egui::CentralPanel::default().show(ui, |ui| self.picture(ui));
        if !ctx.egui_wants_keyboard_input() {
            self.keys(&ctx);
        }
    }

    /// The side panel: cues, sliders, animation, camera, files.
    fn controls(&mut self, ui: &mut egui::Ui) {
        let before = (self.state.enabled(), self.state.request_scene());
        ui.heading("Cues");
        for (i, (cue, on)) in self.state.cues.iter_mut().enumerate() {
            ui.checkbox(on, format!("{} {}", i + 1, cue.key().replace('_', " ")));
        }
        ui.separator();
        ui.heading("Settings");
        let enabled = self.state.enabled();
        for s in &self.state.sliders {
            if s.cue.is_some_and(|c| !enabled.contains(&c)) {
                continue;
            }
            let mut v = (s.get)(&self.state.scene).unwrap_or(s.min);
            if ui
                .add(egui::Slider::new(&mut v, s.min..=s.max).text(s.label))
                .changed()
            {
                (s.set)(&mut self.state.scene, v);
            }
        }
        if enabled.contains(&shapecue::scene::planner::Cue::AmbientOcclusion) {
            choice_combo(ui, "AO level", &mut self.state.scene.effects.ao_mode);
        }
        if enabled.contains(&shapecue::scene::planner::Cue::FeatureEdges) {
            choice_combo(ui, "caps", &mut self.state.scene.effects.caps);
        }
        if self.state.frames.len() > 1 {
            ui.separator();
            ui.heading("Animation");
            ui.horizontal(|ui| {
                let label = if self.state.playing { "pause" } else { "play" };
                if ui.button(label).clicked() {
                    self.state.playing = !self.state.playing;
                }
                let n = self.state.frames.len() - 1;
                ui.add(egui::Slider::new(&mut self.state.frame, 0..=n).text("frame"));
            });
        }
        ui.separator();
        ui.horizontal(|ui| {
            if ui.button("reset view (R)").clicked() {
                self.state.camera.reset();
            }
            if ui.button("PNG (S)").clicked() {
                self.save_png();
            }
            if ui.button("SVG (V)").clicked() {
                self.save_svg();
            }
        });
        if (self.state.enabled(), self.state.request_scene()) != before {
            self.dirty = true;
        }
    }

    /// Frame times and the passes that ran for the frame on screen.
    fn timings(&self, ui: &mut egui::Ui) {
        if let Some(d) = &self.shown {
            ui.add(
                egui::Label::new(format!(
                    "frame {:.1} ms (compute thread), UI {:.1} ms",
                    d.wall_ms, self.ui_frame.1
                ))
                .wrap(),
            );
            if d.dropped > 0 {
                ui.label(format!("{} stale request(s) dropped", d.dropped));
            }
        }
        if let Some(e) = &self.error {
            ui.colored_label(egui::Color32::LIGHT_RED, e);
        }
        if !self.note.is_empty() {
            ui.label(&self.note);
        }
    }

    /// The frame, with the pass overlay; mouse moves the camera.
    fn picture(&mut self, ui: &mut egui::Ui) {
        let Some(tex) = &self.texture else {
            ui.label("drawing the first frame…");
            return;
        };
        let avail = ui.available_size();
        let [w, h] = tex.size().map(|v| v as f32);
        let scale = (avail.x / w).min(avail.y / h).clamp(0.05, 1.0);
        let size = egui::vec2(w * scale, h * scale);
        let resp = ui.add(egui::Image::new((tex.id(), size)).sense(Sense::click_and_drag()));
        let shift = ui.input(|i| i.modifiers.shift);
        let d = resp.drag_delta();
        if d != egui::Vec2::ZERO {
            let cam = &mut self.state.camera;
            if resp.dragged_by(PointerButton::Primary) && !shift {
                cam.orbit(0.4 * d.x, 0.4 * d.y);
            } else {
                cam.pan(d.x / size.y, -d.y / size.y);
            }
            self.dirty = true;
        }
        if resp.hovered() {
            let s = ui.input(|i| i.smooth_scroll_delta.y);
            if s != 0.0 {
                self.state.camera.zoom((-0.002 * s).exp());
                self.dirty = true;
            }
        }
        if let Some(d) = &self.shown {
            let at = resp.rect.left_top() + egui::vec2(6.0, 6.0);
            // The list of passes where it takes at most a third of the
            // picture; else one line, so that a small window still shows
            // its picture.
            let row = ui.text_style_height(&egui::TextStyle::Monospace) + 2.0;
            let list = egui::vec2(54.0 * 0.6 * row, row * (d.passes.len() as f32 + 2.0));
            let fits = list.x * list.y <= resp.rect.area() / 3.0
                && list.x <= resp.rect.width() - 12.0
                && list.y <= resp.rect.height() - 12.0;
            egui::Area::new(egui::Id::unique("passes"))
                .fixed_pos(at)
                .interactable(false)
                .fade_in(false)
                .show(ui.ctx(), |ui| {
                    egui::Frame::popup(ui.style()).show(ui, |ui| {
                        if !fits {
                            ui.label(format!("{:.1} ms, {} passes", d.wall_ms, d.passes.len()));
                            return;
                        }
                        ui.label(format!("{:.1} ms", d.wall_ms));
                        for p in &d.passes {
                            ui.monospace(format!(
                                "{:<20} {:<8} {:>8.2} ms {}",
                                p.pass.name(),
                                p.lifetime.name(),
                                p.ms(),
                                p.clock
                            ));
                        }
                    });
                });
        }
    }

    /// Keys: arrows orbit (with shift: pan), +/- zoom, R reset, space
    /// play/pause, , and . step frames, 1-9 cues, S PNG, V SVG, Q/Esc quit.
    fn keys(&mut self, ctx: &egui::Context) {
        let pressed = |k: Key| ctx.input(|i| i.key_pressed(k));
        let shift = ctx.input(|i| i.modifiers.shift);
        let mut moved = false;
        let cam = &mut self.state.camera;
        for (k, dx, dy) in [
            (Key::ArrowLeft, -1.0, 0.0),
            (Key::ArrowRight, 1.0, 0.0),
            (Key::ArrowUp, 0.0, 1.0),
            (Key::ArrowDown, 0.0, -1.0),
        ] {
            if pressed(k) {
                if shift {
                    cam.pan(-0.05 * dx, -0.05 * dy);
                } else {
                    cam.orbit(10.0 * dx, 10.0 * dy);
                }
                moved = true;
            }
        }
        let before = moved;
        moved = true;
        if pressed(Key::Plus) || pressed(Key::Equals) {
            cam.zoom(0.9);
        } else if pressed(Key::Minus) {
            cam.zoom(1.0 / 0.9);
        } else if pressed(Key::R) || pressed(Key::Home) {
            cam.reset();
        } else if pressed(Key::Space) && self.state.frames.len() > 1 {
            self.state.playing = !self.state.playing;
            moved = before;
        } else if pressed(Key::Comma) {
            self.state.step(-1);
        } else if pressed(Key::Period) {
            self.state.step(1);
        } else if pressed(Key::S) {
            self.save_png();
            moved = before;
        } else if pressed(Key::V) {
            self.save_svg();
            moved = before;
        } else if pressed(Key::C) {
            self.capture = Some(self.free_name("png"));
            moved = before;
        } else if pressed(Key::Q) || pressed(Key::Escape) {
            self.quit = true;
            moved = before;
        } else {
            moved = before;
            let digits = [
                Key::Num1,
                Key::Num2,
                Key::Num3,
                Key::Num4,
                Key::Num5,
                Key::Num6,
                Key::Num7,
                Key::Num8,
                Key::Num9,
            ];
            for (i, k) in digits.into_iter().enumerate() {
                if pressed(k) && i < self.state.cues.len() {
                    self.state.cues[i].1 ^= true;
                    moved = true;
                }
            }
        }
        if moved {
            self.dirty = true;
        }
    }

    fn save_png(&mut self) {
        let p = self.free_name("png");
        self.note = match self.screenshot(&p) {
            Ok(()) => format!("wrote {}", p.display()),
            Err(e) => e.to_string(),
        };
    }

    fn save_svg(&mut self) {
        self.svg_to = Some(self.free_name("svg"));
        self.send(true);
    }
}

/// A combo box over an option enum's choices.
fn choice_combo<T: shapecue::spec::Choice>(ui: &mut egui::Ui, label: &str, v: &mut T) {
    egui::ComboBox::from_label(label)
        .selected_text(v.label())
        .show_ui(ui, |ui| {
            for &c in T::all() {
                ui.selectable_value(v, c, c.label());
            }
        });
}

/// Copies a file the compute thread wrote to where the user wants it.
fn copy(from: &Path, to: &Path) -> Result<()> {
    let bytes = std::fs::read(from)?;
    shapecue::export::output::write_bytes_atomic(to, &bytes)?;
    Ok(())
}
