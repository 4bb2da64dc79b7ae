//! Timed frames of a scene's first view: the view passes run again with
//! the topology, the pose, the device buffers, the GL context and the
//! uploaded mesh kept, as a batch of views reuses them (`shapecue edges
//! --runs`). Medians live here, above the library: a library call runs
//! once and reports its one timing.

use super::metrics::median;
use crate::error::Result;
use crate::gpu::Gpu;
use crate::scene::exec::{ExecOptions, LiveRequest, Session};
use crate::scene::file::Scene;
use std::collections::BTreeMap;
use std::sync::Arc;

/// Medians over the timed frames after the first, ms.
#[derive(Clone, Debug, Default, PartialEq, serde::Serialize)]
pub struct FrameRuns {
    /// Timed frames.
    pub runs: usize,
    /// Median wall time of the whole frame, from the request to its image.
    pub frame_median_ms: f64,
    /// Median kernel time of the frame (OpenCL profiling events).
    pub kernel_median_ms: f64,
    /// Median of each view pass, by pass name.
    pub passes_median_ms: BTreeMap<&'static str, f64>,
}

/// The first view of `scene` drawn `1 + runs` times in one session; the
/// medians of the last `runs`.
///
/// # Errors
/// The scene's errors, device and GL failures.
pub fn timed_frames(gpu: &Arc<Gpu>, scene: &Scene, runs: usize) -> Result<FrameRuns> {
    let req = LiveRequest {
        scene: scene.clone(),
        svg: None,
    };
    let mut frames = Vec::new();
    let mut kernels = Vec::new();
    let mut passes: BTreeMap<&'static str, Vec<f64>> = BTreeMap::new();
    let mut failed = None;
    let mut drawn = 0usize;
    let mut t0 = std::time::Instant::now();
    Session::on(gpu.clone()).live(&ExecOptions::default(), req.clone(), &mut |f| {
        // A frame's time: from the request to its answer, everything in it
        // (the stage, the read-back or compaction, drawing, the image).
        let frame_ms = t0.elapsed().as_secs_f64() * 1e3;
        let f = match f {
            Ok(f) => f,
            Err(e) => {
                failed = Some(e);
                return None;
            }
        };
        // The first frame builds everything: not timed.
        if drawn > 0 {
            frames.push(frame_ms);
            // The kernels of the passes that ran for this frame only.
            let k = f.passes.iter().filter(|p| p.is_kernel()).map(|p| p.ms());
            kernels.push(k.sum());
            for p in &f.passes {
                passes.entry(p.pass.name()).or_default().push(p.ms());
            }
        }
        drawn += 1;
        t0 = std::time::Instant::now();
        (drawn <= runs).then(|| req.clone())
    });
    if let Some(e) = failed {
        return Err(e);
    }
    Ok(FrameRuns {
        runs,
        frame_median_ms: median(&mut frames),
        kernel_median_ms: median(&mut kernels),
        passes_median_ms: passes
            .into_iter()
            .map(|(k, mut v)| (k, median(&mut v)))
            .collect(),
    })
}
