//! The per-pose device pipeline of an animated mesh, in one place:
//! skin ([`Skinner`]) → curvature with dcurv ([`CurvatureEstimator`], f32,
//! positions taken from the skinned buffer) → AO from (k1, k2) ([`AoStage`])
//! → occluding + suggestive contours ([`LineExtractor`]). Every stage reads
//! the previous stage's device buffers; per frame only the joint matrices go
//! up and only the segments (and, on request, the AO values) come back.
//!
//! The bench (`benches/pipeline.rs`) and the report
//! (`shapecue report pipeline`) both drive a frame through
//! [`PosePipeline::frame`], so the bench measures what the report prints.
//!
//! Coordinates: the curvature estimator works in the rest pose's normalized
//! coordinates (fixed for the whole animation, so a pose costs no host
//! reduction); the stages map world-unit parameters (AO radius, eye, feature
//! size) in and segments out.

use crate::error::{Error, Result};
use crate::gpu::{Gpu, wait_ms};
use crate::mesh::skinned::SkinnedMesh;
use crate::spec::ao::AoMode;
use crate::spec::curvature::{CurvatureOptions, Normalization, Precision};
use crate::spec::feature_lines::Segment;
use crate::spec::timing::{Step, Timing};
use crate::spec::view::View;
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
    /// The default pipeline: the default curvature (gather, f32, exact
    /// solve) with dcurv, `lut` AO with a radius of a tenth of the model's
    /// RMS radius.
    fn default() -> Self {
        PipelineOptions {
            curvature: CurvatureOptions::default(),
            ao_mode: AoMode::Lut,
            ao_radius: 0.1,
        }
    }
}

/// One frame of [`PosePipeline::frame`]: the [`Timing`] of its steps
/// (`skin_lbs`, the curvature steps, `ao_vertex`, `lines_vertex`,
/// `lines_face`; per family with [`Timing::family_ms`]) with the frame's
/// host wall time, and the segments read back. Dereferences to the timing.
#[derive(Clone, Debug, Default, PartialEq, Serialize)]
pub struct PassTimes {
    /// Kernel ms per step and the wall time of the frame.
    pub timing: Timing,
    /// Segments read back.
    pub segments: usize,
}

impl std::ops::Deref for PassTimes {
    type Target = Timing;
    fn deref(&self) -> &Timing {
        &self.timing
    }
}

/// Which stages a [`PosePipeline`] builds besides the skinner: the scene
/// executor builds only what its plan runs.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct PipelineStages {
    /// The curvature estimator (needed by AO and the feature lines).
    pub curvature: bool,
    /// The AO stage.
    pub ao: bool,
    /// The feature-line extractor.
    pub lines: bool,
}

impl PipelineStages {
    /// Every stage.
    pub const ALL: PipelineStages = PipelineStages {
        curvature: true,
        ao: true,
        lines: true,
    };
}

/// Skinning, curvature, AO and line extraction of one skinned mesh, every
/// buffer allocated once. Built with every stage ([`PosePipeline::new`]) for
/// the bench and the report, or with the stages a scene's plan runs
/// ([`PosePipeline::with_stages`]) for the scene executor, which drives it
/// pass by pass ([`PosePipeline::skin`], [`PosePipeline::curvature`],
/// [`PosePipeline::run_ao`], [`PosePipeline::lines_at`]).
pub struct PosePipeline {
    skinner: Skinner,
    est: Option<CurvatureEstimator>,
    ao: Option<AoStage>,
    lines: Option<LineExtractor>,
    norm: Normalization,
    feature_size: f32,
    /// AO hemisphere radius, world units.
    ao_radius: f32,
    opts: PipelineOptions,
}

impl PosePipeline {
    /// Uploads the rest mesh, builds every kernel and allocates every buffer.
    pub fn new(gpu: Arc<Gpu>, mesh: &SkinnedMesh, opts: PipelineOptions) -> Result<Self> {
        Self::with_stages(gpu, mesh, opts, PipelineStages::ALL)
    }

    /// [`PosePipeline::new`] building only `stages` (and the skinner). AO
    /// and the lines read the curvature estimator's buffers, so they need
    /// it.
    pub fn with_stages(
        gpu: Arc<Gpu>,
        mesh: &SkinnedMesh,
        opts: PipelineOptions,
        stages: PipelineStages,
    ) -> Result<Self> {
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
        if (stages.ao || stages.lines) && !stages.curvature {
            return Err(Error::InvalidArgument(
                "the pose pipeline's AO and line stages read the curvature estimator".into(),
            ));
        }
        let rest = &mesh.rest;
        let nv = rest.positions.len();
        let used = crate::mesh::referenced(nv, &rest.faces);
        let norm = Normalization::of_masked(&rest.positions, Some(&used));
        Ok(PosePipeline {
            skinner: Skinner::new(gpu.clone(), mesh)?,
            est: match stages.curvature {
                true => Some(CurvatureEstimator::new(
                    gpu.clone(),
                    nv,
                    &rest.faces,
                    opts.curvature,
                )?),
                false => None,
            },
            ao: match stages.ao {
                true => Some(AoStage::new(gpu.clone())?),
                false => None,
            },
            lines: match stages.lines {
                true => Some(LineExtractor::new(gpu, nv, &rest.faces)?),
                false => None,
            },
            norm,
            feature_size: match crate::mesh::feature_size(&rest.positions, &rest.faces) {
                f if f > 0.0 => f as f32,
                _ => Normalization::of(&rest.positions).scale as f32,
            },
            ao_radius: (opts.ao_radius * norm.scale) as f32,
            opts,
        })
    }

    fn est(&self) -> Result<&CurvatureEstimator> {
        self.est.as_ref().ok_or_else(|| {
            Error::InvalidArgument("this pose pipeline was built without curvature".into())
        })
    }

    /// Skins `mats` (column-major, 16 floats per joint) and waits:
    /// step `skin_lbs`.
    pub fn skin(&mut self, mats: &[f32]) -> Result<Timing> {
        let ev = self.skinner.enqueue(mats)?;
        Ok(Timing::of(Step::SkinLbs, wait_ms(ev)?))
    }

    /// Every curvature pass on the skinned positions (in the rest pose's
    /// normalized coordinates), on the device.
    pub fn curvature(&mut self) -> Result<Timing> {
        let Some(est) = self.est.as_mut() else {
            return Err(Error::InvalidArgument(
                "this pose pipeline was built without curvature".into(),
            ));
        };
        est.set_positions_device(&self.skinner.out, [1.0; 3], [0.0; 3], self.norm)?;
        // A new pose: the curve families' per-pose terms are recomputed once,
        // at the first view that needs them.
        if let Some(l) = self.lines.as_mut() {
            l.pose_changed();
        }
        est.run()
    }

    /// Skins `mats`, runs every curvature pass and AO at the options' level;
    /// the results stay on the device.
    pub fn pose(&mut self, mats: &[f32]) -> Result<Timing> {
        let t0 = Instant::now();
        let (mut t, ao) = self.enqueue_pose(mats)?;
        if self.ao.is_some() {
            t.add(Step::AoVertex, wait_ms(ao)?);
        }
        t.wall_ms = t0.elapsed().as_secs_f64() * 1e3;
        Ok(t)
    }

    /// Queues skinning, every curvature pass and AO. The curvature run waits
    /// for its passes (its timing needs them), which also finishes the
    /// skinning queued before it; AO is left running: its event comes back
    /// for the caller to wait on (or to read after a later blocking call).
    fn enqueue_pose(&mut self, mats: &[f32]) -> Result<(Timing, Option<Event>)> {
        let skin = self.skinner.enqueue(mats)?;
        let curvature = self.curvature()?;
        let (radius, mode) = (self.ao_radius, self.opts.ao_mode);
        let est = self.est.as_ref().expect("curvature ran");
        let ao = match self.ao.as_mut() {
            Some(ao) => ao.enqueue_device(est, radius, mode)?,
            None => None,
        };
        let mut t = Timing::of(Step::SkinLbs, wait_ms(skin)?);
        t.extend(&curvature);
        t.wall_ms = 0.0;
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
        self.lines_at(view, feature_size, opts, [0.0; 3])
    }

    /// [`PosePipeline::lines`] with the eye and the segments relative to
    /// `origin` ([`LineExtractor::extract_device_at`]).
    pub fn lines_at(
        &mut self,
        view: View,
        feature_size: f32,
        opts: LineOptions,
        origin: [f64; 3],
    ) -> Result<(Vec<Segment>, LineStats)> {
        let (Some(lines), Some(est)) = (self.lines.as_mut(), self.est.as_ref()) else {
            return Err(Error::InvalidArgument(
                "this pose pipeline was built without the line stage".into(),
            ));
        };
        lines.extract_device_at(est, view, feature_size, opts, origin)
    }

    /// One frame: [`PosePipeline::pose`] then [`PosePipeline::lines`], with
    /// no host wait between AO and the lines (the in-order queue keeps them
    /// in order); the times of every step and the wall time of both.
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
        if self.ao.is_some() {
            t.add(Step::AoVertex, wait_ms(ao)?);
        }
        t.extend(&st.timing);
        t.wall_ms = t0.elapsed().as_secs_f64() * 1e3;
        let segments = st.segments;
        Ok((
            segs,
            PassTimes {
                timing: t,
                segments,
            },
        ))
    }

    /// Sets the AO hemisphere radius in world units (by default the
    /// options' fraction of the rest pose's RMS radius).
    pub fn set_ao_radius(&mut self, radius: f32) {
        self.ao_radius = radius;
    }

    /// Reruns AO on the current curvatures at `mode` (e.g. to compare
    /// levels): step `ao_vertex`.
    pub fn run_ao(&mut self, mode: AoMode) -> Result<Timing> {
        let radius = self.ao_radius;
        let (Some(ao), Some(est)) = (self.ao.as_mut(), self.est.as_ref()) else {
            return Err(Error::InvalidArgument(
                "this pose pipeline was built without AO".into(),
            ));
        };
        Ok(Timing::of(
            Step::AoVertex,
            ao.run_device(est, radius, mode)?,
        ))
    }

    /// [`PosePipeline::run_ao`]'s kernel ms.
    pub fn ao(&mut self, mode: AoMode) -> Result<f64> {
        Ok(self.run_ao(mode)?.kernel_ms)
    }

    /// The AO values of the last AO run, one per vertex.
    pub fn read_ao(&self) -> Result<Vec<f32>> {
        match &self.ao {
            Some(ao) => ao.read(self.skinner.n_vertices()),
            None => Err(Error::InvalidArgument(
                "this pose pipeline was built without AO".into(),
            )),
        }
    }

    /// AO hemisphere radius in world units.
    pub fn ao_radius(&self) -> f32 {
        self.ao_radius
    }

    /// The rest pose's normalization (fixed for every pose).
    pub fn normalization(&self) -> Normalization {
        self.norm
    }

    /// The curvature estimator (its last run is the current pose), if built.
    pub fn estimator(&self) -> Option<&CurvatureEstimator> {
        self.est().ok()
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
        View::from_eye(std::array::from_fn(|i| (c[i] + s * d[i]) as f32), false)
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
