//! The per-pose device pipeline of an animated mesh, in one place:
//! skin ([`Skinner`]) → curvature with dcurv ([`CurvatureEstimator`], f32,
//! positions taken from the skinned buffer) → AO from (k1, k2) ([`AoStage`])
//! → occluding + suggestive contours ([`LineExtractor`]). Every stage reads
//! the previous stage's device buffers; per frame only the joint matrices go
//! up and only the segments (and, on request, the AO values) come back.
//!
//! The bench (`benches/pipeline.rs`) and the report
//! ([`crate::report::pipeline_report`]) both drive a frame through
//! [`PosePipeline::frame`], so the bench measures what the report prints.
//!
//! Coordinates: the curvature estimator works in the rest pose's normalized
//! coordinates (fixed for the whole animation, so a pose costs no host
//! reduction); the stages map world-unit parameters (AO radius, eye, feature
//! size) in and segments out.

use crate::cpu::ao::AoMode;
use crate::cpu::feature_lines::{Segment, View};
use crate::error::{Error, Result};
use crate::field::{Accumulate, Compat, CurvatureOptions, Normalization, Precision};
use crate::gpu::{Gpu, wait_ms};
use crate::mesh::skinned::SkinnedMesh;
use crate::stages::ao::AoStage;
use crate::stages::curvature::CurvatureEstimator;
use crate::stages::feature_lines::{LineExtractor, LineOptions, LineStats};
use crate::stages::skinning::Skinner;
use opencl3::event::Event;
use serde::Serialize;
use std::sync::Arc;
use std::time::Instant;

/// What the pipeline computes per pose.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct PipelineOptions {
    /// Curvature variant; must be f32 (device chaining), dcurv on for
    /// suggestive contours.
    pub curvature: CurvatureOptions,
    /// AO accuracy level of [`PosePipeline::pose`].
    pub ao_mode: AoMode,
    /// AO hemisphere radius as a fraction of the rest pose's RMS radius
    /// (the normalization scale), so one value suits every model.
    pub ao_radius: f64,
}

impl Default for PipelineOptions {
    /// The default pipeline: atomic f32 curvature with dcurv, `lut` AO with a
    /// radius of a tenth of the model's RMS radius.
    fn default() -> Self {
        PipelineOptions {
            curvature: CurvatureOptions {
                accumulate: Accumulate::Atomic,
                precision: Precision::F32,
                compat: Compat::Exact,
                dcurv: true,
            },
            ao_mode: AoMode::Lut,
            ao_radius: 0.1,
        }
    }
}

/// Kernel ms of each pass of one frame (OpenCL profiling events) and the
/// frame's host wall time.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize)]
pub struct PassTimes {
    /// `skin_lbs`.
    pub skin_ms: f64,
    /// Every curvature pass including dcurv (and the position load).
    pub curvature_ms: f64,
    /// `ao_vertex`.
    pub ao_ms: f64,
    /// `lines_vertex` + `lines_face` (0 from [`PosePipeline::pose`]).
    pub lines_ms: f64,
    /// Segments read back (0 from [`PosePipeline::pose`]).
    pub segments: usize,
    /// Host wall time of the call, uploads and read-backs included.
    pub wall_ms: f64,
}

impl PassTimes {
    /// Sum of the kernel times.
    pub fn kernel_ms(&self) -> f64 {
        self.skin_ms + self.curvature_ms + self.ao_ms + self.lines_ms
    }
}

/// Skinning, curvature, AO and line extraction of one skinned mesh, every
/// buffer allocated once.
pub struct PosePipeline {
    skinner: Skinner,
    est: CurvatureEstimator,
    ao: AoStage,
    lines: LineExtractor,
    norm: Normalization,
    feature_size: f32,
    opts: PipelineOptions,
}

impl PosePipeline {
    /// Uploads the rest mesh, builds every kernel and allocates every buffer.
    pub fn new(gpu: Arc<Gpu>, mesh: &SkinnedMesh, opts: PipelineOptions) -> Result<Self> {
        if opts.curvature.precision != Precision::F32 {
            return Err(Error::InvalidArgument(
                "the pose pipeline chains stages on the device and needs f32 curvature".into(),
            ));
        }
        if !(opts.ao_radius.is_finite() && opts.ao_radius > 0.0) {
            return Err(Error::InvalidArgument(format!(
                "AO radius (fraction of the model size) must be finite and positive, got {}",
                opts.ao_radius
            )));
        }
        let rest = &mesh.rest;
        let nv = rest.positions.len();
        let used = crate::mesh::referenced(nv, &rest.faces);
        Ok(PosePipeline {
            skinner: Skinner::new(gpu.clone(), mesh)?,
            est: CurvatureEstimator::new(gpu.clone(), nv, &rest.faces, opts.curvature)?,
            ao: AoStage::new(gpu.clone())?,
            lines: LineExtractor::new(gpu, nv, &rest.faces)?,
            norm: Normalization::of_masked(&rest.positions, Some(&used)),
            feature_size: match crate::mesh::feature_size(&rest.positions, &rest.faces) {
                f if f > 0.0 => f as f32,
                _ => Normalization::of(&rest.positions).scale as f32,
            },
            opts,
        })
    }

    /// Skins `mats` (column-major, 16 floats per joint), runs every curvature
    /// pass and AO at the options' level; the results stay on the device.
    pub fn pose(&mut self, mats: &[f32]) -> Result<PassTimes> {
        let t0 = Instant::now();
        let (mut t, ao) = self.enqueue_pose(mats)?;
        t.ao_ms = wait_ms(ao)?;
        t.wall_ms = t0.elapsed().as_secs_f64() * 1e3;
        Ok(t)
    }

    /// Queues skinning, every curvature pass and AO. The curvature run waits
    /// for its passes (its timing needs them), which also finishes the
    /// skinning queued before it; AO is left running: its event comes back
    /// for the caller to wait on (or to read after a later blocking call).
    fn enqueue_pose(&mut self, mats: &[f32]) -> Result<(PassTimes, Option<Event>)> {
        let skin = self.skinner.enqueue(mats)?;
        self.est
            .set_positions_device(&self.skinner.out, [1.0; 3], [0.0; 3], self.norm)?;
        let curvature_ms = self.est.run()?.kernel_ms;
        let ao = self
            .ao
            .enqueue_device(&self.est, self.ao_radius(), self.opts.ao_mode)?;
        let t = PassTimes {
            skin_ms: wait_ms(skin)?,
            curvature_ms,
            ..Default::default()
        };
        Ok((t, ao))
    }

    /// Contours and suggestive contours of the current pose from `view`
    /// (world units, like `feature_size`); segments in world coordinates.
    pub fn lines(
        &mut self,
        view: View,
        feature_size: f32,
        opts: LineOptions,
    ) -> Result<(Vec<Segment>, LineStats)> {
        self.lines
            .extract_device(&self.est, view, feature_size, opts)
    }

    /// One frame: [`PosePipeline::pose`] then [`PosePipeline::lines`], with
    /// no host wait between AO and the lines (the in-order queue keeps them
    /// in order); the times of every pass and the wall time of both.
    pub fn frame(
        &mut self,
        mats: &[f32],
        view: View,
        feature_size: f32,
        opts: LineOptions,
    ) -> Result<(Vec<Segment>, PassTimes)> {
        let t0 = Instant::now();
        let (mut t, ao) = self.enqueue_pose(mats)?;
        let (segs, st) = self.lines(view, feature_size, opts)?;
        t.ao_ms = wait_ms(ao)?;
        t.lines_ms = st.vertex_ms + st.face_ms;
        t.segments = st.segments;
        t.wall_ms = t0.elapsed().as_secs_f64() * 1e3;
        Ok((segs, t))
    }

    /// Reruns AO on the current curvatures at `mode` (e.g. to compare
    /// levels); returns the kernel ms.
    pub fn ao(&mut self, mode: AoMode) -> Result<f64> {
        self.ao.run_device(&self.est, self.ao_radius(), mode)
    }

    /// The AO values of the last AO run, one per vertex.
    pub fn read_ao(&self) -> Result<Vec<f32>> {
        self.ao.read(self.skinner.n_vertices())
    }

    /// AO hemisphere radius in world units.
    pub fn ao_radius(&self) -> f32 {
        (self.opts.ao_radius * self.norm.scale) as f32
    }

    /// The rest pose's normalization (fixed for every pose).
    pub fn normalization(&self) -> Normalization {
        self.norm
    }

    /// The curvature estimator (its last run is the current pose).
    pub fn estimator(&self) -> &CurvatureEstimator {
        &self.est
    }

    /// The skinner (its output buffer is the current pose).
    pub fn skinner(&self) -> &Skinner {
        &self.skinner
    }

    /// A perspective view of the rest pose from the front (+z, glTF's
    /// forward), a little to the side and above, three RMS radii away:
    /// the view the bench and the report use.
    pub fn front_view(&self) -> View {
        let (c, s) = (self.norm.center, self.norm.scale);
        let d = [0.8, 0.6, 2.8];
        View {
            eye: std::array::from_fn(|i| (c[i] + s * d[i]) as f32),
            ortho: false,
        }
    }

    /// Feature size for the suggestive-contour threshold: the rest pose's
    /// median edge length ([`crate::mesh::feature_size`]), as the scene
    /// executor uses.
    pub fn feature_size(&self) -> f32 {
        self.feature_size
    }
}

/// Joint matrices of `frames` poses evenly spaced over the first clip (the
/// rest pose repeated when the file has no clip), flattened for
/// [`PosePipeline::pose`].
pub fn clip_poses(mesh: &SkinnedMesh, frames: usize) -> Result<Vec<Vec<f32>>> {
    let frames = frames.max(1);
    (0..frames)
        .map(|f| {
            let m = match mesh.clips.first() {
                Some(c) => mesh.joint_matrices(Some(0), c.duration * f as f32 / frames as f32)?,
                None => mesh.joint_matrices(None, 0.0)?,
            };
            Ok(SkinnedMesh::flatten(&m))
        })
        .collect()
}
