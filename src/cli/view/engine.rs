//! The viewer's compute thread: it owns the OpenCL device and the headless
//! renderer (one [`Session`] of the scene executor, so the device's programs
//! and the GL context are made once) and draws each frame the window asks
//! for through the executor's live scene, with the passes `shapecue render`
//! would run, less those whose results still hold: a camera move reruns
//! the view passes only, a new frame the pose passes and the view passes.
//!
//! Requests carry a whole scene (one camera, one frame, the cues and
//! sliders of the moment). The thread always takes the newest request and
//! drops the ones that a newer one made stale, so a slow frame never queues
//! up behind the mouse; the window's event loop never waits for it.

use shapecue::scene::exec::{ExecOptions, LiveRequest, PassRecord, Session};
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
            ..Default::default()
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

/// The newest of the requests waiting (blocking for one when none is),
/// and how many older ones it made stale; `None` once the window is gone.
/// A dropped request's SVG goes on with the newer one.
fn newest(rx: &Receiver<Request>) -> Option<(Request, u64)> {
    let mut req = rx.recv().ok()?;
    let mut dropped = 0;
    loop {
        match rx.try_recv() {
            Ok(newer) => {
                dropped += 1;
                let svg = req.svg || newer.svg;
                req = newer;
                req.svg = svg;
            }
            Err(TryRecvError::Empty) => return Some((req, dropped)),
            Err(TryRecvError::Disconnected) => return None,
        }
    }
}

/// The request as the executor's live scene takes it: the image in
/// memory, the SVG (when asked for) under a name of its own, so that the
/// next frame does not overwrite it before the window copies it.
fn live_request(req: Request, dir: &std::path::Path) -> LiveRequest {
    let mut scene = req.scene;
    scene.png = false;
    scene.svg = false;
    LiveRequest {
        svg: req.svg.then(|| dir.join(format!("lines-{}.svg", req.id))),
        scene,
    }
}

/// The thread's loop: the scene held live by the executor (a camera move
/// reruns only the view passes, a new frame the pose passes), newest
/// request first, stale ones dropped.
fn serve(rx: Receiver<Request>, tx: Sender<Reply>, opts: ExecOptions, wake: Box<dyn Fn() + Send>) {
    let dir = opts.out_dir.clone().unwrap_or_default();
    let Some((first, mut dropped)) = newest(&rx) else {
        return;
    };
    let mut id = first.id;
    let mut t0 = Instant::now();
    let mut session = Session::new();
    session.live(&opts, live_request(first, &dir), &mut |result| {
        let reply = match result {
            Ok(f) => match f.view.image {
                Some(image) => Reply::Frame(Box::new(Done {
                    id,
                    image: image.to_image(),
                    passes: f.passes,
                    wall_ms: t0.elapsed().as_secs_f64() * 1e3,
                    svg: f.svg,
                    dropped,
                })),
                None => Reply::Failed(id, "the scene drew no frame".into()),
            },
            Err(e) => Reply::Failed(id, e.to_string()),
        };
        tx.send(reply).ok()?;
        wake();
        let (req, d) = newest(&rx)?;
        (id, dropped, t0) = (req.id, d, Instant::now());
        Some(live_request(req, &dir))
    });
}
