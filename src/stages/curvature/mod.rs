//! Host wiring of the curvature kernels (`kernels/curvature.cl` with one of
//! `kernels/curvature_atomic.cl`, `kernels/curvature_gather.cl`): per-vertex
//! normals, point areas, principal curvatures and directions, and the
//! curvature derivative.
//!
//! [`CurvatureEstimator`] owns every device buffer. Topology-only data (face
//! indices, owning faces, one-ring lists) is uploaded and computed once in
//! [`CurvatureEstimator::new`]; [`CurvatureEstimator::set_positions`] uploads a
//! new pose into the existing buffers and [`CurvatureEstimator::run`] reruns
//! only the position-dependent passes, so a deforming mesh costs no
//! reallocation per frame (Griffin et al. 2012, §3.6). The accumulation
//! schemes' own kernels and buffers are wired in `atomic.rs` and `gather.rs`,
//! the program build in `build.rs`, the read-backs in `read.rs`, and the
//! memory-ordered and one-shot estimators in `ordered.rs`. The CPU twin is
//! [`crate::cpu::curvature`]; shared types, thresholds and the memory bound:
//! [`crate::spec::curvature`]; one-ring lists: [`crate::mesh::topology`].

mod atomic;
mod build;
mod gather;
mod ordered;
mod read;

pub use build::{KernelBuild, build_kernels, build_options};
pub use ordered::{OrderPlan, OrderedEstimator, estimate};
pub use read::MappedField;

use crate::error::{Error, Result};
use crate::gpu::{Arg, Gpu, buf, event_ms, launch};
use crate::spec::curvature::{
    Accumulate, CurvatureCounts, CurvatureOptions, Normalization, Precision, REC_REALS,
    padded_faces, padded_vertices,
};
use crate::spec::timing::{Step, Timing};
use build::{Built, Kernels, SchemeKernels};
use opencl3::event::Event;
use opencl3::memory::Buffer;
use serde::Serialize;
use std::sync::Arc;
use std::time::Instant;

/// The passes of the stage, in execution order. `MaxFace` is topology-only.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Pass {
    /// Owning face per vertex (atomic_max, or the last one-ring entry in the
    /// gather variant); once per topology.
    MaxFace,
    /// Zero the accumulators (atomic variant only).
    Clear,
    /// Corner-weighted normals and Voronoi point areas.
    NormalsAreas,
    /// Unit normals and the initial per-vertex frames.
    Frames,
    /// Per-face curvature tensors summed over the one-ring.
    Tensor,
    /// Diagonalisation: k1, k2, d1, d2.
    Principal,
    /// Curvature derivative.
    Dcurv,
}

impl Pass {
    /// The pass name used in stats and reports: its timing step's name
    /// (the kernel entry point without `curv_`).
    pub fn name(self) -> &'static str {
        self.step().name()
    }
}

impl Pass {
    /// The timing step of this pass (its kernel entry point `curv_<name>`).
    pub fn step(self) -> Step {
        match self {
            Pass::MaxFace => Step::CurvMaxFace,
            Pass::Clear => Step::CurvClear,
            Pass::NormalsAreas => Step::CurvNormalsAreas,
            Pass::Frames => Step::CurvFrames,
            Pass::Tensor => Step::CurvTensor,
            Pass::Principal => Step::CurvPrincipal,
            Pass::Dcurv => Step::CurvDcurv,
        }
    }
}

/// Device state after a partial run, for pass-by-pass comparison with the
/// CPU reference. All values in normalized coordinates.
#[derive(Clone, Debug, Default)]
pub struct Intermediate {
    /// Normals (raw sums before `Frames`, unit after).
    pub normals: Vec<[f64; 3]>,
    /// Point areas.
    pub areas: Vec<f64>,
    /// First frame vector (initial frame before `Principal`, d1 after).
    pub pd1: Vec<[f64; 3]>,
    /// Second frame vector.
    pub pd2: Vec<[f64; 3]>,
    /// (ku, kuv, kv) in the initial frame.
    pub tensor: Vec<[f64; 3]>,
    /// (k1, k2).
    pub k: Vec<[f64; 2]>,
    /// Derivative tensor.
    pub dk: Vec<[f64; 4]>,
}

/// Borrowed device buffers of the last run, for stages that chain on the
/// device ([`crate::stages::ao::AoStage::run_device`],
/// [`crate::stages::feature_lines::LineExtractor::extract_device`]). Values
/// are f32 in *normalized* coordinates (`p' = (p − center)/scale`, see
/// [`Normalization`]): curvatures are multiplied by `scale` and the
/// derivative by `scale²` relative to the world. Lengths in floats: `pos`,
/// `nrm`, `d1`, `d2` 3·nv; `k` (k1, k2) 2·nv; `dk` 4·nv. After a run up to
/// [`Pass::Frames`] only `pos` and `nrm` are current (enough for occluding
/// contours), `d1`, `d2` hold the initial tangent frames, and `k`, `dk` the
/// previous run's values, or zeros (zeroed at allocation).
pub struct DeviceOutputs<'a> {
    /// Vertices.
    pub nv: usize,
    /// Normalized positions.
    pub pos: &'a Buffer<u8>,
    /// Unit normals.
    pub nrm: &'a Buffer<u8>,
    /// First principal directions.
    pub d1: &'a Buffer<u8>,
    /// Second principal directions.
    pub d2: &'a Buffer<u8>,
    /// (k1, k2), normalized.
    pub k: &'a Buffer<u8>,
    /// Curvature derivative (C111, C112, C122, C222), normalized.
    pub dk: &'a Buffer<u8>,
    /// The pose's normalization, to map results back to world units.
    pub norm: Normalization,
}

/// A mesh's curvature estimator on one device.
pub struct CurvatureEstimator {
    gpu: Arc<Gpu>,
    opts: CurvatureOptions,
    nv: usize,
    nf: usize,
    real: usize,
    norm: Normalization,
    referenced: Vec<bool>,
    staging: Vec<u8>,
    k: Kernels,
    /// The accumulation scheme's kernels (and the gather scheme's buffers).
    scheme: Scheme,
    faces: Buffer<u32>,
    owner: Buffer<i32>,
    /// With lanes (either scheme): 16 reals per vertex (`REC_*` in
    /// kernels/common/curvature_lanes.h), what the tensor and derivative face
    /// kernels read of each vertex.
    rec: Option<Buffer<u8>>,
    pos: Buffer<u8>,
    nrm: Buffer<u8>,
    area: Buffer<u8>,
    pd1: Buffer<u8>,
    pd2: Buffer<u8>,
    tens: Buffer<u8>,
    kk: Buffer<u8>,
    dk: Buffer<u8>,
    counters: Buffer<u32>,
    normal_override: Option<Buffer<f32>>,
    device_bytes: u64,
    /// Host clocks: `program_build`, `topology`, and of the last pose
    /// `normalise` and `upload` ([`CurvatureEstimator::host_timing`]).
    host: Timing,
}

/// The accumulation scheme an estimator runs, with what it holds of its own.
enum Scheme {
    /// Float atomic adds per face ([`atomic`]).
    Atomic(atomic::Kernels),
    /// Corners per face, then ring sums per vertex ([`gather`]).
    Gather(gather::Gather),
}

impl Scheme {
    /// Enqueues a one-ring pass as this scheme runs it.
    fn one_ring(&self, g: &Gpu, r: &OneRing) -> Result<Vec<(Pass, Event)>> {
        match self {
            Scheme::Atomic(a) => a.one_ring(g, r),
            Scheme::Gather(x) => x.one_ring(g, r),
        }
    }
}

/// A one-ring pass (normals and areas, tensor or derivative) as either
/// scheme launches it.
struct OneRing<'a> {
    /// [`Pass::NormalsAreas`], [`Pass::Tensor`] or [`Pass::Dcurv`].
    pass: Pass,
    /// The face kernel's inputs (after the face count).
    face_args: &'a [Arg],
    /// The per-vertex sums the pass writes.
    outputs: &'a [Arg],
    /// The skip counters.
    counters: Arg,
    nv: usize,
    nf: usize,
    /// Faces per work-item of the face kernel.
    lanes: u32,
}

/// The estimator's buffers as the passes take them, and the vertex records
/// of either scheme with lanes (see `Kernels`).
#[derive(Clone, Copy)]
struct PassArgs {
    pos: Arg,
    faces: Arg,
    cnt: Arg,
    nrm: Arg,
    area: Arg,
    pd1: Arg,
    pd2: Arg,
    tens: Arg,
    kk: Arg,
    dk: Arg,
    rec: Option<Arg>,
}

impl OneRing<'_> {
    /// The pass's place in each scheme's kernel triples.
    fn index(&self) -> usize {
        match self.pass {
            Pass::NormalsAreas => 0,
            Pass::Tensor => 1,
            Pass::Dcurv => 2,
            p => unreachable!("{p:?} is not a one-ring pass"),
        }
    }
}

/// A mesh's faces as an estimator gets them: in a device buffer, and on the
/// host too where they came from there.
struct Faces<'a> {
    /// Vertices of the mesh.
    nv: usize,
    /// Faces (the buffer may hold padding past them).
    nf: usize,
    /// Face indices on the device.
    buffer: Buffer<u32>,
    /// The same faces on the host (`None`: a mesh that lives on the device).
    host: Option<&'a [[u32; 3]]>,
}

impl CurvatureEstimator {
    /// Allocates every buffer for a mesh with `n_vertices` vertices and these
    /// faces, builds the kernels for `opts` and runs the topology-only passes.
    /// Face indices must be in range (see [`crate::Mesh::validate`]).
    pub fn new(
        gpu: Arc<Gpu>,
        n_vertices: usize,
        faces: &[[u32; 3]],
        opts: CurvatureOptions,
    ) -> Result<Self> {
        crate::mesh::check_faces(n_vertices, faces, "curvature estimator")?;
        let built = Self::build(&gpu, &opts)?;
        let flat: &[u32] = bytemuck::cast_slice(faces);
        // Whole blocks of MAX_FACE_LANES faces, the last face repeated in the
        // padding: the per-face kernels with lanes load a block's face
        // indices at constant offsets, with no clamp at the last face.
        let len = 3 * padded_faces(faces.len());
        let mut faces_b = gpu.buffer::<u32>(len)?;
        if let Some(last) = faces.last() {
            gpu.write_with(&mut faces_b, len, |b| {
                let (head, pad) = b.split_at_mut(flat.len());
                head.copy_from_slice(flat);
                for f in pad.chunks_exact_mut(3) {
                    f.copy_from_slice(last);
                }
            })?;
        }
        let faces = Faces {
            nv: n_vertices,
            nf: faces.len(),
            buffer: faces_b,
            host: Some(faces),
        };
        Self::with_faces(gpu, faces, opts, built)
    }

    /// Like [`CurvatureEstimator::new`] for a mesh whose faces are already on
    /// the device (e.g. a fused isosurface). Every vertex must be used by a
    /// face (as after vertex fusion's compaction). The atomic schemes copy
    /// the faces on the device, with no host round trip; gather builds its
    /// one-ring lists on the host, so it reads the faces back once (12 bytes
    /// a face) and then runs as [`CurvatureEstimator::new`]. Positions come
    /// from [`CurvatureEstimator::set_positions_device`].
    pub fn from_device(
        gpu: Arc<Gpu>,
        n_vertices: usize,
        faces: &Buffer<u32>,
        n_faces: usize,
        opts: CurvatureOptions,
    ) -> Result<Self> {
        if opts.accumulate == Accumulate::Gather {
            let mut host = vec![[0u32; 3]; n_faces];
            gpu.read(faces, &mut bytemuck::cast_slice_mut(&mut host)[..])?;
            return Self::new(gpu, n_vertices, &host, opts);
        }
        let mut faces_b = gpu.buffer::<u32>(3 * n_faces)?;
        if n_faces > 0 {
            // SAFETY: both buffers hold at least 3·n_faces u32.
            unsafe {
                gpu.queue()
                    .enqueue_copy_buffer(faces, &mut faces_b, 0, 0, 12 * n_faces, &[])
            }
            .map_err(|e| Error::cl("clEnqueueCopyBuffer", e))?;
        }
        // One face per work-item: the face kernels with lanes read the faces
        // in whole blocks, which this buffer, copied as it is, does not hold.
        let opts = CurvatureOptions {
            lanes: crate::spec::curvature::Lanes::Fixed(1),
            ..opts
        };
        let built = Self::build(&gpu, &opts)?;
        let faces = Faces {
            nv: n_vertices,
            nf: n_faces,
            buffer: faces_b,
            host: None,
        };
        Self::with_faces(gpu, faces, opts, built)
    }

    /// Allocates the buffers of a mesh whose faces are on the device, builds
    /// its topology-only data with the program in `built`, and zeroes the
    /// rest.
    fn with_faces(
        gpu: Arc<Gpu>,
        faces: Faces<'_>,
        opts: CurvatureOptions,
        built: Built,
    ) -> Result<Self> {
        let Built {
            k,
            scheme,
            program,
            t0,
            build_ms,
        } = built;
        let (nv, nf) = (faces.nv, faces.nf);
        let real = opts.precision.bytes();
        if let SchemeKernels::Gather(_) = scheme {
            gather::check_faces(nf)?;
        }
        // Per-vertex buffers hold whole blocks of MAX_FACE_LANES vertices: the
        // per-vertex kernels with lanes read and write whole blocks.
        let nvp = padded_vertices(nv);
        let mut owner = gpu.buffer::<i32>(nvp)?;
        let mut bufs = build::vertex_buffers(&gpu, nvp, real)?;
        let scheme = build::topology(&gpu, scheme, &program, &faces, &mut owner, &mut bufs, real)?;
        gpu.finish()?;
        let [pos, nrm, area, pd1, pd2, tens, kk, dk]: [Buffer<u8>; 8] = bufs
            .try_into()
            .unwrap_or_else(|_| unreachable!("one buffer per entry of REALS"));
        // With lanes, curv_frames and curv_principal also write the vertex
        // records (written whole by curv_frames before any kernel reads them).
        let rec = if k.lanes > 1 {
            Some(gpu.buffer::<u8>(REC_REALS * nvp * real)?)
        } else {
            None
        };
        let est = CurvatureEstimator {
            rec,
            pos,
            nrm,
            area,
            pd1,
            pd2,
            tens,
            kk,
            dk,
            counters: gpu.buffer::<u32>(4)?,
            normal_override: None,
            device_bytes: crate::spec::curvature::device_bytes_bound(nv, nf, &opts, k.lanes),
            gpu,
            opts,
            nv,
            nf,
            real,
            norm: Normalization {
                center: [0.0; 3],
                scale: 1.0,
            },
            referenced: match faces.host {
                Some(f) => crate::mesh::referenced(nv, f),
                None => vec![true; nv],
            },
            staging: Vec::with_capacity(3 * nv * real),
            k,
            faces: faces.buffer,
            owner,
            scheme,
            host: {
                let mut t = Timing::default();
                t.phase("program_build", build_ms);
                t.phase("topology", t0.elapsed().as_secs_f64() * 1e3 - build_ms);
                t
            },
        };
        Ok(est)
    }

    /// Replaces the owning faces that seed each vertex's initial tangent
    /// frame (by default the largest face id using the vertex, as in
    /// trimesh2; −1 for none). A mesh computed in another order passes the
    /// images of its input's owners ([`LocalityOrder::frame_faces`]), so its
    /// principal directions keep the signs they have in the input order. A
    /// face that does not use its vertex only seeds another tangent frame.
    pub fn set_frame_faces(&mut self, owner: &[i32]) -> Result<()> {
        if owner.len() != self.nv {
            return Err(Error::InvalidArgument(format!(
                "{} frame faces given for {} vertices",
                owner.len(),
                self.nv
            )));
        }
        if let Some((v, &f)) = owner
            .iter()
            .enumerate()
            .find(|&(_, &f)| f < -1 || i64::from(f) >= self.nf as i64)
        {
            return Err(Error::InvalidArgument(format!(
                "frame face {f} of vertex {v} is not a face of this mesh ({} faces)",
                self.nf
            )));
        }
        self.gpu.write(&mut self.owner, owner)
    }

    /// Faces per work-item of the per-face kernels as built for this device
    /// (also vertices per work-item of the frame and principal kernels; 1 for
    /// a mesh already on the device).
    pub fn face_lanes(&self) -> u32 {
        self.k.lanes
    }

    /// The variant this estimator runs.
    pub fn options(&self) -> &CurvatureOptions {
        &self.opts
    }

    /// Device bytes held by this estimator.
    pub fn device_bytes(&self) -> u64 {
        self.device_bytes
    }

    /// The estimator's host clocks, as phases: `program_build` (getting
    /// the program and creating the kernels: a build from source, from
    /// shapecue's binary cache, or nothing when this `Gpu` built it
    /// before), `topology` (the topology-only data, the build left out),
    /// and of the last [`CurvatureEstimator::set_positions`] `normalise`
    /// (validating the pose, its centre and scale) and `upload` (converting
    /// to the device precision and the blocking write).
    pub fn host_timing(&self) -> &Timing {
        &self.host
    }

    /// Wall time of setting the estimator up for its topology: the
    /// `program_build` and `topology` phases of
    /// [`CurvatureEstimator::host_timing`].
    pub fn topology_ms(&self) -> f64 {
        self.host.phase_ms("program_build") + self.host.phase_ms("topology")
    }

    /// Wall time of getting the program and creating the kernels: the
    /// `program_build` phase of [`CurvatureEstimator::host_timing`].
    pub fn build_ms(&self) -> f64 {
        self.host.phase_ms("program_build")
    }

    /// The device this estimator runs on.
    pub fn gpu(&self) -> &Arc<Gpu> {
        &self.gpu
    }

    /// Uploads a new pose (same vertex count) into the existing position
    /// buffer: centred and scaled in f64 on the host (over the vertices faces use), then rounded to the
    /// device precision. No allocation after the first call.
    pub fn set_positions(&mut self, positions: &[[f64; 3]]) -> Result<()> {
        if positions.len() != self.nv {
            return Err(Error::InvalidArgument(format!(
                "pose has {} vertices, the estimator was built for {}",
                positions.len(),
                self.nv
            )));
        }
        let t0 = Instant::now();
        crate::mesh::check_positions(positions, "pose")?;
        self.norm = Normalization::of_masked(positions, Some(&self.referenced));
        let t1 = Instant::now();
        self.staging.clear();
        for (p, &used) in positions.iter().zip(&self.referenced) {
            // Unreferenced vertices are never read; zeros keep them finite in f32.
            let q = if used { self.norm.apply(*p) } else { [0.0; 3] };
            for c in q {
                match self.opts.precision {
                    Precision::F32 => self.staging.extend_from_slice(&(c as f32).to_ne_bytes()),
                    Precision::F64 => self.staging.extend_from_slice(&c.to_ne_bytes()),
                }
            }
        }
        self.gpu.write(&mut self.pos, &self.staging)?;
        self.host
            .set_phase("normalise", (t1 - t0).as_secs_f64() * 1e3);
        self.host
            .set_phase("upload", t1.elapsed().as_secs_f64() * 1e3);
        Ok(())
    }

    /// Loads positions from a device buffer of `3·n_vertices` floats `p`
    /// (e.g. a fused isosurface in voxel index space) whose world position is
    /// `origin + spacing ⊙ p`, normalized on the device with `norm`
    /// (results are mapped back with it). No host round trip.
    pub fn set_positions_device(
        &mut self,
        src: &Buffer<f32>,
        spacing: [f64; 3],
        origin: [f64; 3],
        norm: Normalization,
    ) -> Result<()> {
        if !(norm.scale.is_finite() && norm.scale > 0.0) {
            return Err(Error::InvalidArgument(format!(
                "normalization scale must be finite and positive, got {}",
                norm.scale
            )));
        }
        self.norm = norm;
        // normalized = (origin + spacing·p − center) / scale = a·p + b
        let a: [f64; 3] = std::array::from_fn(|i| spacing[i] / norm.scale);
        let b: [f64; 3] = std::array::from_fn(|i| (origin[i] - norm.center[i]) / norm.scale);
        let real = |v: f64| match self.opts.precision {
            Precision::F32 => Arg::F32(v as f32),
            Precision::F64 => Arg::F64(v),
        };
        let mut args = vec![Arg::U32(self.nv as u32), buf(src)];
        args.extend(a.iter().chain(&b).map(|&v| real(v)));
        args.push(buf(&self.pos));
        launch(&self.gpu, &self.k.load_positions, self.nv, &args)?;
        Ok(())
    }

    /// Uses these unit normals (3 floats per vertex, e.g. from an
    /// isosurface's volume gradient: see
    /// [`crate::stages::marching_cubes::Isosurfacer::gradient_normals`])
    /// instead of the area-weighted face normals in every later pass, where
    /// they are finite and non-zero. `None` goes back to the mesh normals.
    pub fn set_normal_override(&mut self, normals: Option<Buffer<f32>>) {
        self.normal_override = normals;
    }

    /// Starts every later run from these vertex normals (a mesh file's
    /// stored normals, [`crate::Mesh::normals`], one per vertex; scaled to
    /// unit length by the frames pass), as trimesh2 starts from the normals
    /// a file stores. `None` goes back to the computed normals.
    ///
    /// # Errors
    /// A count other than the vertices'; OpenCL failures.
    pub fn set_stored_normals(&mut self, normals: Option<&[[f32; 3]]>) -> Result<()> {
        let Some(n) = normals else {
            self.normal_override = None;
            return Ok(());
        };
        if n.len() != self.nv {
            return Err(Error::InvalidArgument(format!(
                "{} stored normals for a mesh of {} vertices",
                n.len(),
                self.nv
            )));
        }
        let flat: Vec<f32> = n.iter().flatten().copied().collect();
        let mut b = self.gpu.buffer::<f32>(flat.len().max(1))?;
        if !flat.is_empty() {
            self.gpu.write(&mut b, &flat)?;
        }
        self.normal_override = Some(b);
        Ok(())
    }

    /// The normalization of the current pose.
    pub fn normalization(&self) -> Normalization {
        self.norm
    }

    /// Runs every position-dependent pass on the current pose.
    pub fn run(&mut self) -> Result<Timing> {
        self.run_until(Pass::Dcurv)
    }

    /// Runs the position-dependent passes up to and including `last`
    /// (the dcurv pass only if the options ask for it).
    pub fn run_until(&mut self, last: Pass) -> Result<Timing> {
        let t0 = Instant::now();
        // Not a blocking write: the skinning or position load queued before
        // this run keeps going while the passes are enqueued.
        self.gpu.zero(&mut self.counters, 4)?;
        let g = &*self.gpu;
        let mut events: Vec<(Pass, Event)> = Vec::new();
        let a = self.pass_args();
        let dcurv = self.opts.dcurv && Pass::Dcurv <= last;
        if let Scheme::Atomic(s) = &self.scheme {
            let sums = [a.nrm, a.area, a.tens, a.dk];
            events.extend(s.clear(g, self.nv, sums)?.map(|e| (Pass::Clear, e)));
        }
        if Pass::NormalsAreas <= last {
            self.normals_areas(&a, &mut events)?;
        }
        if Pass::Frames <= last {
            self.frames(&a, &mut events)?;
        }
        if Pass::Tensor <= last {
            let args: &[Arg] = match &a.rec {
                Some(r) => &[*r, a.faces],
                None => &[a.pos, a.faces, a.nrm, a.area, a.pd1, a.pd2],
            };
            events.extend(self.one_ring(Pass::Tensor, args, &[a.tens], a.cnt)?);
        }
        if Pass::Principal <= last {
            self.principal(&a, &mut events)?;
        }
        if dcurv {
            let args: &[Arg] = match &a.rec {
                Some(r) => &[*r, a.faces],
                None => &[a.pos, a.faces, a.area, a.pd1, a.pd2, a.kk],
            };
            events.extend(self.one_ring(Pass::Dcurv, args, &[a.dk], a.cnt)?);
        }
        g.finish()?;
        let wall_ms = t0.elapsed().as_secs_f64() * 1e3;
        // One entry per pass: a gather pass's face and sum kernels are added up.
        let mut timing = Timing::default();
        for (p, e) in &events {
            timing.add(p.step(), event_ms(e));
        }
        timing.wall_ms = wall_ms;
        Ok(timing)
    }

    /// The buffers the passes read and write, as kernel arguments.
    fn pass_args(&self) -> PassArgs {
        PassArgs {
            pos: buf(&self.pos),
            faces: buf(&self.faces),
            cnt: buf(&self.counters),
            nrm: buf(&self.nrm),
            area: buf(&self.area),
            pd1: buf(&self.pd1),
            pd2: buf(&self.pd2),
            tens: buf(&self.tens),
            kk: buf(&self.kk),
            dk: buf(&self.dk),
            rec: self.rec.as_ref().map(buf),
        }
    }

    /// A one-ring pass as the scheme runs it (atomic: adds from each face;
    /// gather: corners per face, then ring sums per vertex).
    fn one_ring(
        &self,
        pass: Pass,
        face_args: &[Arg],
        outputs: &[Arg],
        counters: Arg,
    ) -> Result<Vec<(Pass, Event)>> {
        let r = OneRing {
            pass,
            face_args,
            outputs,
            counters,
            nv: self.nv,
            nf: self.nf,
            lanes: self.k.lanes,
        };
        self.scheme.one_ring(&self.gpu, &r)
    }

    /// The normals and areas pass, then the normals given in their place
    /// where there are some.
    fn normals_areas(&self, a: &PassArgs, events: &mut Vec<(Pass, Event)>) -> Result<()> {
        let (pos, faces, nrm, area) = (a.pos, a.faces, a.nrm, a.area);
        events.extend(self.one_ring(Pass::NormalsAreas, &[pos, faces], &[nrm, area], a.cnt)?);
        if let Some(src) = &self.normal_override {
            let args = [Arg::U32(self.nv as u32), buf(src), nrm];
            let ev = launch(&self.gpu, &self.k.override_normals, self.nv, &args)?;
            events.extend(ev.map(|e| (Pass::NormalsAreas, e)));
        }
        Ok(())
    }

    /// `curv_frames` (one work-item per block of `lanes` vertices), and
    /// without lanes the count of vertices without faces.
    fn frames(&self, a: &PassArgs, events: &mut Vec<(Pass, Event)>) -> Result<()> {
        let (g, nv32) = (&*self.gpu, self.nv as u32);
        let vblocks = self.nv.div_ceil(self.k.lanes as usize);
        let (pos, faces, nrm, pd1, pd2) = (a.pos, a.faces, a.nrm, a.pd1, a.pd2);
        let mut args = vec![Arg::U32(nv32), pos, faces, buf(&self.owner), nrm, pd1, pd2];
        args.extend(a.rec.map(|r| [a.area, r, a.cnt]).into_iter().flatten());
        let ev = launch(g, &self.k.frames, vblocks, &args)?;
        events.extend(ev.map(|e| (Pass::Frames, e)));
        if a.rec.is_none() {
            // (curv_frames with lanes counts these itself)
            let args = [Arg::U32(nv32), a.area, a.cnt];
            let ev = launch(g, &self.k.count_empty, self.nv, &args)?;
            events.extend(ev.map(|e| (Pass::Frames, e)));
        }
        Ok(())
    }

    /// `curv_principal` (one work-item per block of `lanes` vertices).
    fn principal(&self, a: &PassArgs, events: &mut Vec<(Pass, Event)>) -> Result<()> {
        let vblocks = self.nv.div_ceil(self.k.lanes as usize);
        let mut args = vec![Arg::U32(self.nv as u32), a.nrm, a.tens, a.pd1, a.pd2, a.kk];
        args.extend(a.rec.map(|r| [a.pos, a.area, r]).into_iter().flatten());
        let ev = launch(&self.gpu, &self.k.principal, vblocks, &args)?;
        events.extend(ev.map(|e| (Pass::Principal, e)));
        Ok(())
    }

    /// The device buffers of the last run, for chaining later stages on the
    /// device without a host round trip. Only f32 buffers can be chained (the
    /// line and AO kernels are f32): an f64 estimator is refused.
    pub fn device_outputs(&self) -> Result<DeviceOutputs<'_>> {
        if self.opts.precision != Precision::F32 {
            return Err(Error::InvalidArgument(
                "device chaining needs f32 precision (this curvature estimator runs f64; \
                 use precision = f32, or read the field back)"
                    .into(),
            ));
        }
        Ok(DeviceOutputs {
            nv: self.nv,
            pos: &self.pos,
            nrm: &self.nrm,
            d1: &self.pd1,
            d2: &self.pd2,
            k: &self.kk,
            dk: &self.dk,
            norm: self.norm,
        })
    }

    /// What the last run had to skip.
    pub fn counts(&self) -> Result<CurvatureCounts> {
        let mut c = [0u32; 4];
        self.gpu.read(&self.counters, &mut c)?;
        Ok(CurvatureCounts {
            degenerate_faces: c[0],
            vertices_without_curvature: c[1],
            tensor_solves_skipped: c[2],
            dcurv_solves_skipped: c[3],
        })
    }
}

/// Where the gather scheme's one-ring lists are built: on the device for
/// devices with their own memory (GPUs: the host build writes scattered
/// entries through a mapping), on the host for CPU devices (the lists land
/// in the buffers themselves). `SHAPECUE_RING_BUILD=device` or `host` overrides it.
fn rings_on_device(gpu: &Gpu) -> bool {
    match std::env::var("SHAPECUE_RING_BUILD").as_deref() {
        Ok("device") => true,
        Ok("host") => false,
        _ => !gpu.info.kind.eq_ignore_ascii_case("CPU"),
    }
}
