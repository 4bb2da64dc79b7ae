//! The viewer's compute thread: it owns the OpenCL device and the headless
//! renderer (one [`Session`] of the scene executor, so the device's programs
//! and the GL context are made once) and draws each frame the window asks
//! for through the executor, exactly as `shapecue render` would draw it.
//!
//! Requests carry a whole scene (one camera, one frame, the cues and
//! sliders of the moment). The thread always takes the newest request and
//! drops the ones that a newer one made stale, so a slow frame never queues
//! up behind the mouse; the window's event loop never waits for it.

use shapecue::scene::exec::{ExecOptions, PassRecord, Session, output_paths};
use shapecue::scene::file::Scene;
use std::path::PathBuf;
use std::sync::mpsc::{Receiver, Sender, TryRecvError, channel};
use std::thread::JoinHandle;
use std::time::Instant;

/// One frame to draw.
pub struct Request {
    /// Increases with every request.
    pub id: u64,
    /// The scene with one camera, one frame and the current cues.
    pub scene: Scene,
    /// Also write the SVG of the lines (a dropped request hands its SVG on).
    pub svg: bool,
}

/// A drawn frame.
pub struct Done {
    /// The request it answers.
    pub id: u64,
    /// RGBA8 image, row 0 at the top.
    pub image: image::RgbaImage,
    /// The passes that ran for it, in plan order, with their ms.
    pub passes: Vec<PassRecord>,
    /// Wall time of the whole frame on the compute thread (ms).
    pub wall_ms: f64,
    /// The SVG file of the lines, when asked for.
    pub svg: Option<PathBuf>,
    /// The requests dropped as stale since the last frame.
    pub dropped: u64,
}

/// What the compute thread answers.
pub enum Reply {
    /// A frame.
    Frame(Box<Done>),
    /// A request failed: the error in words.
    Failed(u64, String),
}

/// The compute thread and its channels.
pub struct Engine {
    tx: Option<Sender<Request>>,
    pub rx: Receiver<Reply>,
    thread: Option<JoinHandle<()>>,
    dir: PathBuf,
}

impl Engine {
    /// Starts the thread; `wake` is called after each reply (to wake the
    /// window's event loop).
    pub fn start(device: Option<String>, wake: Box<dyn Fn() + Send>) -> std::io::Result<Engine> {
        let dir = std::env::temp_dir().join(format!("shapecue-view-{}", std::process::id()));
        std::fs::create_dir_all(&dir)?;
        let (tx, req_rx) = channel::<Request>();
        let (reply_tx, rx) = channel::<Reply>();
        let opts = ExecOptions {
            out_dir: Some(dir.clone()),
            force: true,
            device,
        };
        let thread = std::thread::Builder::new()
            .name("shapecue-view-compute".into())
            .spawn(move || serve(req_rx, reply_tx, opts, wake))?;
        Ok(Engine {
            tx: Some(tx),
            rx,
            thread: Some(thread),
            dir,
        })
    }

    /// Queues a request (the thread drops it if a newer one comes first).
    pub fn send(&self, r: Request) {
        if let Some(tx) = &self.tx {
            // The thread ends only when the engine is dropped.
            let _ = tx.send(r);
        }
    }
}

impl Drop for Engine {
    fn drop(&mut self) {
        self.tx = None;
        if let Some(t) = self.thread.take() {
            let _ = t.join();
        }
        let _ = std::fs::remove_dir_all(&self.dir);
    }
}

/// The thread's loop: newest request first, stale ones dropped.
fn serve(rx: Receiver<Request>, tx: Sender<Reply>, opts: ExecOptions, wake: Box<dyn Fn() + Send>) {
    let mut session = Session::new();
    while let Ok(mut req) = rx.recv() {
        let mut dropped = 0;
        loop {
            match rx.try_recv() {
                Ok(newer) => {
                    dropped += 1;
                    let svg = req.svg || newer.svg;
                    req = newer;
                    req.svg = svg;
                }
                Err(TryRecvError::Empty) => break,
                Err(TryRecvError::Disconnected) => return,
            }
        }
        let id = req.id;
        let reply = match draw(&mut session, req, &opts) {
            Ok(mut d) => {
                d.dropped = dropped;
                Reply::Frame(Box::new(d))
            }
            Err(e) => Reply::Failed(id, e),
        };
        if tx.send(reply).is_err() {
            return;
        }
        wake();
    }
}

/// Draws one request through the executor and reads its image back.
fn draw(session: &mut Session, req: Request, opts: &ExecOptions) -> Result<Done, String> {
    let t0 = Instant::now();
    let id = req.id;
    let mut scene = req.scene;
    scene.png = true;
    scene.svg = req.svg;
    let report = session
        .run(&scene, opts, &mut |_, _| {})
        .map_err(|e| e.to_string())?;
    let dir = opts.out_dir.clone().unwrap_or_default();
    let (images, _) = output_paths(&scene, &report.frames, &dir);
    let is = |p: &PathBuf, ext: &str| p.extension().is_some_and(|e| e == ext);
    let png = images
        .iter()
        .map(|i| &i.2)
        .find(|p| is(p, "png"))
        .ok_or("the executor wrote no image")?;
    let image = image::open(png)
        .map_err(|e| format!("{}: {e}", png.display()))?
        .to_rgba8();
    // A name of its own, so that the next frame does not overwrite it before
    // the window copies it.
    let svg = match images.iter().map(|i| &i.2).find(|p| is(p, "svg")) {
        Some(p) => {
            let own = dir.join(format!("lines-{id}.svg"));
            std::fs::rename(p, &own).map_err(|e| format!("{}: {e}", p.display()))?;
            Some(own)
        }
        None => None,
    };
    Ok(Done {
        id,
        image,
        passes: report.passes,
        wall_ms: t0.elapsed().as_secs_f64() * 1e3,
        svg,
        dropped: 0,
    })
}
