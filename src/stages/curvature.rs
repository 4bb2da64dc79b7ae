//! Host wiring of `kernels/curvature.cl`: per-vertex normals, point areas,
//! principal curvatures and directions, and the curvature derivative.
//!
//! [`CurvatureEstimator`] owns every device buffer. Topology-only data (face
//! indices, owning faces, one-ring lists) is uploaded and computed once in
//! [`CurvatureEstimator::new`]; [`CurvatureEstimator::set_positions`] uploads a
//! new pose into the existing buffers and [`CurvatureEstimator::run`] reruns
//! only the position-dependent passes, so a deforming mesh costs no
//! reallocation per frame (Griffin et al. 2012, §3.6). The CPU twin is
//! [`crate::cpu::curvature`]; shared types, thresholds and the memory bound:
//! [`crate::spec::curvature`]; one-ring lists: [`crate::mesh::topology`].

use crate::error::{Error, Result};
use crate::gpu::{Arg, Gpu, Mapped, buf, event_ms, kernel_file, launch};
use crate::mesh::order::{LocalityOrder, MeshOrder};
use crate::mesh::topology::{one_rings_into, owners_from_rings};
use crate::spec::curvature::{
    Accumulate, Compat, CurvatureCounts, CurvatureField, CurvatureOptions, Normalization,
    Precision, REC_REALS, VertexCurvature, corner_reals_bound, corner_weights_bound, padded_faces,
    padded_vertices,
};
use crate::spec::timing::{Step, Timing};
use opencl3::kernel::Kernel;
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
    /// The pass name used in stats and reports.
    pub fn name(self) -> &'static str {
        match self {
            Pass::MaxFace => "max_face",
            Pass::Clear => "clear",
            Pass::NormalsAreas => "normals_areas",
            Pass::Frames => "frames",
            Pass::Tensor => "tensor",
            Pass::Principal => "principal",
            Pass::Dcurv => "dcurv",
        }
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
    faces: Buffer<u32>,
    owner: Buffer<i32>,
    gather: Option<GatherBufs>,
    /// With lanes (either scheme): 16 reals per vertex (`REC_*` in
    /// kernels/curvature.cl), what the tensor and derivative face kernels
    /// read of each vertex.
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
    topology_ms: f64,
    build_ms: f64,
    upload_ms: UploadMs,
}

/// Host time of the last [`CurvatureEstimator::set_positions`], in ms.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize)]
pub struct UploadMs {
    /// Validating the pose and computing its normalization (centre, scale).
    pub normalise: f64,
    /// Converting to the device precision and the blocking write.
    pub write: f64,
}

struct Kernels {
    /// Atomic variant only: zeroes the accumulators.
    clear: Option<Kernel>,
    /// Atomic variant: the per-face scatter kernel; gather: the per-face corner kernel.
    normals_areas: Kernel,
    frames: Kernel,
    count_empty: Kernel,
    tensor: Kernel,
    principal: Kernel,
    dcurv: Kernel,
    /// Gather variant only: the per-vertex one-ring sums of the three passes.
    sums: Option<[Kernel; 3]>,
    /// Positions from a device buffer of index-space floats (isosurfaces).
    load_positions: Kernel,
    /// Given unit normals replace the accumulated ones (isosurfaces).
    override_normals: Kernel,
    /// Faces per work-item of the per-face kernels, and vertices per
    /// work-item of the frame and principal kernels: `SC_LANES` of the build.
    lanes: u32,
}

/// Buffers of the gather variant: one-ring lists and corner contributions.
struct GatherBufs {
    ring_off: Buffer<u32>,
    ring: Buffer<u32>,
    corner: Buffer<u8>,
    /// Corner areas, then weights, of each face corner (3 reals per face).
    cw: Buffer<u8>,
}

/// Build options of `kernels/curvature.cl` for a variant, with `lanes` faces
/// per work-item in the per-face kernels; `pair_adds`: the compare-and-swap
/// scheme in f32 adds two adjacent floats in one 64-bit compare-and-swap
/// where it can (the device has `cl_khr_int64_base_atomics`).
pub fn build_options(opts: &CurvatureOptions, lanes: u32, pair_adds: bool) -> String {
    let mut s = String::new();
    if pair_adds && opts.accumulate == Accumulate::Atomic && opts.precision == Precision::F32 {
        s.push_str("-DSC_PAIR_ADDS ");
    }
    if opts.accumulate == Accumulate::Gather {
        // The program then holds the gather kernels only, not the atomic ones
        // (PoCL builds it from source about 5 % sooner).
        s.push_str("-DSC_GATHER ");
    }
    if lanes > 1 {
        s.push_str(&format!("-DSC_LANES={lanes} "));
    }
    if opts.accumulate == Accumulate::AtomicNative {
        // atomic_fetch_add_explicit on atomic_float needs OpenCL C 2.0 or later
        s.push_str("-cl-std=CL3.0 -DSC_NATIVE_ATOMICS ");
    }
    if opts.precision == Precision::F64 {
        s.push_str("-DSC_DOUBLE ");
    }
    if opts.compat == Compat::Trimesh2 {
        s.push_str("-DSC_COMPAT ");
    }
    s.trim_end().to_string()
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
        let t0 = Instant::now();
        let (k, program) = Self::build(&gpu, &opts)?;
        let build_ms = t0.elapsed().as_secs_f64() * 1e3;
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
        Self::with_faces(
            gpu,
            n_vertices,
            faces_b,
            faces.len(),
            Some(faces),
            opts,
            k,
            program,
            (t0, build_ms),
        )
    }

    /// Gets the program an estimator for `opts` runs into `gpu`'s table of
    /// built programs (from source, shapecue's binary cache or the driver's),
    /// so that a later [`CurvatureEstimator::new`] on `gpu` finds it built.
    /// It needs no mesh: a caller can run it beside the mesh's load.
    ///
    /// # Errors
    ///
    /// As [`CurvatureEstimator::new`] for options the device cannot run,
    /// and OpenCL build errors.
    pub fn prepare(gpu: &Arc<Gpu>, opts: &CurvatureOptions) -> Result<()> {
        Self::build(gpu, opts).map(drop)
    }

    /// Gets the program for `opts` built into `gpu` (as [`Self::prepare`])
    /// and runs every pass of it once on a small icosphere (642 vertices), so
    /// that the code a runtime compiles at a kernel's first launch (PoCL: a
    /// work-group function per kernel and local size) is compiled too and
    /// goes into the binary that [`Gpu::persist_programs`] saves. Returns
    /// the run's timing.
    ///
    /// # Errors
    ///
    /// As [`CurvatureEstimator::new`] and [`CurvatureEstimator::run`].
    pub fn warm_up(gpu: &Arc<Gpu>, opts: &CurvatureOptions) -> Result<Timing> {
        let (_, mesh) = crate::mesh::Generated::Sphere.mesh(642);
        let mut est = CurvatureEstimator::new(gpu.clone(), mesh.n_vertices(), &mesh.faces, *opts)?;
        est.set_positions(&mesh.positions)?;
        est.run()
    }

    fn build(
        gpu: &Arc<Gpu>,
        opts: &CurvatureOptions,
    ) -> Result<(Kernels, Arc<opencl3::program::Program>)> {
        if opts.precision == Precision::F64 {
            if !gpu.info.fp64 {
                return Err(Error::DeviceUnsupported {
                    device: gpu.info.name.clone(),
                    what: "--precision f64 needs cl_khr_fp64".into(),
                });
            }
            if opts.accumulate == Accumulate::Atomic && !gpu.info.int64_atomics {
                return Err(Error::DeviceUnsupported {
                    device: gpu.info.name.clone(),
                    what: "f64 atomic accumulation needs cl_khr_int64_base_atomics; \
                           use --accumulate gather"
                        .into(),
                });
            }
        }
        let native = match opts.precision {
            Precision::F32 => gpu.info.float_atomics,
            Precision::F64 => gpu.info.double_atomics,
        };
        if opts.accumulate == Accumulate::AtomicNative && !native {
            return Err(Error::DeviceUnsupported {
                device: gpu.info.name.clone(),
                what: format!(
                    "--accumulate atomic-native needs native {} float atomic adds \
                     (cl_ext_float_atomics); use --accumulate atomic or gather",
                    opts.precision.name()
                ),
            });
        }
        if !matches!(opts.lanes, 0 | 1 | 2 | 4 | 8 | 16) {
            return Err(Error::InvalidArgument(format!(
                "face lanes must be 1, 2, 4, 8 or 16 (or 0: by device type), not {}",
                opts.lanes
            )));
        }
        let native = match opts.precision {
            Precision::F32 => gpu.info.native_float_width,
            Precision::F64 => gpu.info.native_double_width,
        };
        let lanes = crate::spec::curvature::face_lanes_for(opts.lanes, &gpu.info.kind, native);
        let file = kernel_file("curvature").expect("curvature kernels are embedded");
        let pair_adds = gpu.info.int64_atomics;
        let program = gpu.program(&file, &build_options(opts, lanes, pair_adds))?;
        let gather = opts.accumulate == Accumulate::Gather;
        let kname = |base: &str| {
            if gather {
                format!("{base}_corners")
            } else {
                base.to_string()
            }
        };
        let sums = if gather {
            Some([
                gpu.kernel(&program, "curv_normals_areas_sum")?,
                gpu.kernel(&program, "curv_tensor_sum")?,
                gpu.kernel(&program, "curv_dcurv_sum")?,
            ])
        } else {
            None
        };
        let k = Kernels {
            clear: if gather {
                None
            } else {
                Some(gpu.kernel(&program, "curv_clear")?)
            },
            normals_areas: gpu.kernel(&program, &kname("curv_normals_areas"))?,
            frames: gpu.kernel(&program, "curv_frames")?,
            count_empty: gpu.kernel(&program, "curv_count_empty")?,
            tensor: gpu.kernel(&program, &kname("curv_tensor"))?,
            principal: gpu.kernel(&program, "curv_principal")?,
            dcurv: gpu.kernel(&program, &kname("curv_dcurv"))?,
            sums,
            load_positions: gpu.kernel(&program, "curv_load_positions")?,
            override_normals: gpu.kernel(&program, "curv_override_normals")?,
            lanes,
        };
        Ok((k, program))
    }

    /// Like [`CurvatureEstimator::new`] for a mesh whose faces are already on
    /// the device (e.g. a fused isosurface): no host round trip. Every vertex
    /// must be used by a face (as after vertex fusion's compaction). The
    /// gather variant needs one-ring lists built on the host and is refused
    /// here; positions come from [`CurvatureEstimator::set_positions_device`].
    pub fn from_device(
        gpu: Arc<Gpu>,
        n_vertices: usize,
        faces: &Buffer<u32>,
        n_faces: usize,
        opts: CurvatureOptions,
    ) -> Result<Self> {
        if opts.accumulate == Accumulate::Gather {
            return Err(Error::InvalidArgument(
                "curvature of a device-resident mesh uses --accumulate atomic \
                 (the gather variant builds its one-ring lists on the host)"
                    .into(),
            ));
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
        let opts = CurvatureOptions { lanes: 1, ..opts };
        let t0 = Instant::now();
        let (k, program) = Self::build(&gpu, &opts)?;
        let build_ms = t0.elapsed().as_secs_f64() * 1e3;
        Self::with_faces(
            gpu,
            n_vertices,
            faces_b,
            n_faces,
            None,
            opts,
            k,
            program,
            (t0, build_ms),
        )
    }

    #[allow(clippy::too_many_arguments)]
    fn with_faces(
        gpu: Arc<Gpu>,
        nv: usize,
        faces_b: Buffer<u32>,
        nf: usize,
        faces: Option<&[[u32; 3]]>,
        opts: CurvatureOptions,
        k: Kernels,
        program: Arc<opencl3::program::Program>,
        (t0, build_ms): (Instant, f64),
    ) -> Result<Self> {
        let gather = opts.accumulate == Accumulate::Gather;
        let real = opts.precision.bytes();
        if gather && corner_reals_bound(nf) > u32::MAX as usize {
            return Err(Error::InvalidArgument(format!(
                "{nf} faces are more than the gather scheme's 32-bit corner slots address \
                 ({} at most); use --accumulate atomic",
                u32::MAX as usize / 12 - crate::spec::curvature::MAX_FACE_LANES as usize
            )));
        }
        // Per-vertex buffers hold whole blocks of MAX_FACE_LANES vertices: the
        // per-vertex kernels with lanes read and write whole blocks.
        let nvp = padded_vertices(nv);
        let mut owner = gpu.buffer::<i32>(nvp)?;
        // Zeroed once: a partial run (normals only, for contours) leaves the
        // curvature buffers unwritten, and later stages reading them through
        // [`CurvatureEstimator::device_outputs`] must see finite values.
        // Reals per vertex of pos, nrm, area, pd1, pd2, tens, kk, dk.
        const REALS: [usize; 8] = [3, 3, 1, 3, 3, 3, 2, 4];
        // The positions have one real more: the normal pass with lanes loads
        // each vertex's x y z as 4 reals (kernels/curvature.cl, ld_pos).
        let reals = |i: usize, n: usize| n * nvp + usize::from(i == 0);
        let mut bufs = REALS
            .iter()
            .enumerate()
            .map(|(i, &n)| gpu.buffer::<u8>(reals(i, n) * real))
            .collect::<Result<Vec<_>>>()?;
        // The fills are enqueued (no host zeros) and run on the device
        // beside the host's work below; the one `finish` at the end waits
        // for them. On a CPU device they are also the first touch of the
        // buffers' pages, which then costs the host nothing: on the 2M
        // torus the topology phase went from 259-304 to 191-214 ms.
        let zero_all = |bufs: &mut [Buffer<u8>]| -> Result<()> {
            for (i, (b, n)) in bufs.iter_mut().zip(REALS).enumerate() {
                gpu.zero(b, reals(i, n) * real)?;
            }
            gpu.flush()
        };
        let gather_bufs = if gather {
            // The one-ring lists are built in the device buffers themselves
            // (mapped: no host copy on CPU runtimes), and the owning faces are
            // their last entries, so no curv_max_face pass runs. The fills
            // are enqueued once the maps are made (a blocking map waits for
            // what the queue holds), so they run while the lists are built.
            let faces = faces.unwrap_or(&[]);
            let mut ring_off = gpu.buffer::<u32>(nv + 1)?;
            let ring_len = crate::spec::curvature::one_ring_len_bound(nf);
            let mut ring_b = gpu.buffer::<u32>(ring_len)?;
            gpu.write_with(&mut ring_off, nv + 1, |off| {
                gpu.write_with(&mut ring_b, ring_len, |ring| {
                    gpu.write_with(&mut owner, nvp, |o| {
                        zero_all(&mut bufs)?;
                        one_rings_into(faces, off, ring);
                        let (o, pad) = o.split_at_mut(nv);
                        owners_from_rings(off, ring, o);
                        pad.fill(-1);
                        Ok::<(), Error>(())
                    })
                })
            })????;
            Some(GatherBufs {
                ring_off,
                ring: ring_b,
                corner: gpu.buffer::<u8>(corner_reals_bound(nf) * real)?,
                cw: gpu.buffer::<u8>(corner_weights_bound(nf) * real)?,
            })
        } else {
            zero_all(&mut bufs)?;
            None
        };
        if !gather {
            let max_face = gpu.kernel(&program, "curv_max_face")?;
            gpu.write(&mut owner, &vec![-1i32; nvp])?;
            launch(
                &gpu,
                &max_face,
                nf,
                &[Arg::U32(nf as u32), buf(&faces_b), buf(&owner)],
            )?;
        }
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
            referenced: match faces {
                Some(f) => crate::mesh::referenced(nv, f),
                None => vec![true; nv],
            },
            staging: Vec::with_capacity(3 * nv * real),
            k,
            faces: faces_b,
            owner,
            gather: gather_bufs,
            topology_ms: t0.elapsed().as_secs_f64() * 1e3,
            build_ms,
            upload_ms: UploadMs::default(),
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

    /// Wall time of building the topology-only data (includes the first
    /// program build of the process).
    pub fn topology_ms(&self) -> f64 {
        self.topology_ms
    }

    /// Wall time of getting the program and creating the kernels (part of
    /// [`CurvatureEstimator::topology_ms`]): a build from source, from
    /// shapecue's binary cache, or nothing when this `Gpu` built it before.
    pub fn build_ms(&self) -> f64 {
        self.build_ms
    }

    /// Host time of the last [`CurvatureEstimator::set_positions`].
    pub fn upload_ms(&self) -> UploadMs {
        self.upload_ms
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
        self.upload_ms = UploadMs {
            normalise: (t1 - t0).as_secs_f64() * 1e3,
            write: t1.elapsed().as_secs_f64() * 1e3,
        };
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
        let g = &*self.gpu;
        let (nv, nf) = (self.nv, self.nf);
        let (nv32, nf32) = (nv as u32, nf as u32);
        let t0 = Instant::now();
        // Not a blocking write: the skinning or position load queued before
        // this run keeps going while the passes are enqueued.
        g.zero(&mut self.counters, 4)?;
        let mut events: Vec<(Pass, opencl3::event::Event)> = Vec::new();
        let mut record = |pass: Pass, ev: Option<opencl3::event::Event>| {
            if let Some(e) = ev {
                events.push((pass, e));
            }
        };
        let (pos, faces, cnt) = (buf(&self.pos), buf(&self.faces), buf(&self.counters));
        let (nrm, area, pd1, pd2) = (
            buf(&self.nrm),
            buf(&self.area),
            buf(&self.pd1),
            buf(&self.pd2),
        );
        let (tens, kk, dk) = (buf(&self.tens), buf(&self.kk), buf(&self.dk));
        let dcurv = self.opts.dcurv && Pass::Dcurv <= last;
        // Work-items of curv_frames and curv_principal: one per block of
        // `lanes` vertices.
        let vblocks = nv.div_ceil(self.k.lanes as usize);

        // A one-ring pass: the atomic variant scatters from its face kernel (args
        // + output + counters); the gather variant writes corners, then sums them.
        let one_ring = |face_kernel: &Kernel,
                        face_args: &[Arg],
                        sum: usize,
                        outputs: &[Arg],
                        pass: Pass|
         -> Result<Vec<(Pass, opencl3::event::Event)>> {
            let mut evs = Vec::new();
            match (&self.gather, &self.k.sums) {
                (Some(gb), Some(sums)) => {
                    let mut a = vec![Arg::U32(nf32)];
                    a.extend_from_slice(face_args);
                    a.extend([buf(&gb.corner), buf(&gb.cw), cnt]);
                    // One work-item per block of `lanes` faces.
                    let blocks = nf.div_ceil(self.k.lanes as usize);
                    evs.extend(launch(g, face_kernel, blocks, &a)?.map(|e| (pass, e)));
                    let mut a = vec![
                        Arg::U32(nv32),
                        buf(&gb.ring_off),
                        buf(&gb.ring),
                        buf(&gb.corner),
                    ];
                    a.extend_from_slice(outputs);
                    evs.extend(launch(g, &sums[sum], nv, &a)?.map(|e| (pass, e)));
                }
                _ => {
                    let mut a = vec![Arg::U32(nf32)];
                    a.extend_from_slice(face_args);
                    a.extend_from_slice(outputs);
                    a.push(cnt);
                    // One work-item per block of `lanes` faces.
                    let blocks = nf.div_ceil(self.k.lanes as usize);
                    evs.extend(launch(g, face_kernel, blocks, &a)?.map(|e| (pass, e)));
                }
            }
            Ok(evs)
        };

        if let Some(clear) = &self.k.clear {
            let ev = launch(g, clear, nv, &[Arg::U32(nv32), nrm, area, tens, dk])?;
            record(Pass::Clear, ev);
        }
        if Pass::NormalsAreas <= last {
            for (p, e) in one_ring(
                &self.k.normals_areas,
                &[pos, faces],
                0,
                &[nrm, area],
                Pass::NormalsAreas,
            )? {
                record(p, Some(e));
            }
            if let Some(src) = &self.normal_override {
                let args = [Arg::U32(nv32), buf(src), nrm];
                record(
                    Pass::NormalsAreas,
                    launch(g, &self.k.override_normals, nv, &args)?,
                );
            }
        }
        // The vertex records of either scheme with lanes (see `Kernels`).
        let rec = self.rec.as_ref().map(buf);
        if Pass::Frames <= last {
            let mut args = vec![Arg::U32(nv32), pos, faces, buf(&self.owner), nrm, pd1, pd2];
            args.extend(rec.map(|r| [area, r, cnt]).into_iter().flatten());
            record(Pass::Frames, launch(g, &self.k.frames, vblocks, &args)?);
            if rec.is_none() {
                // (curv_frames with lanes counts these itself)
                let args = [Arg::U32(nv32), area, cnt];
                record(Pass::Frames, launch(g, &self.k.count_empty, nv, &args)?);
            }
        }
        if Pass::Tensor <= last {
            let args: &[Arg] = match &rec {
                Some(r) => &[*r, faces],
                None => &[pos, faces, nrm, area, pd1, pd2],
            };
            for (p, e) in one_ring(&self.k.tensor, args, 1, &[tens], Pass::Tensor)? {
                record(p, Some(e));
            }
        }
        if Pass::Principal <= last {
            let mut args = vec![Arg::U32(nv32), nrm, tens, pd1, pd2, kk];
            args.extend(rec.map(|r| [pos, area, r]).into_iter().flatten());
            record(
                Pass::Principal,
                launch(g, &self.k.principal, vblocks, &args)?,
            );
        }
        if dcurv {
            let args: &[Arg] = match &rec {
                Some(r) => &[*r, faces],
                None => &[pos, faces, area, pd1, pd2, kk],
            };
            for (p, e) in one_ring(&self.k.dcurv, args, 2, &[dk], Pass::Dcurv)? {
                record(p, Some(e));
            }
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

    /// The device buffers of the last run, for chaining later stages on the
    /// device without a host round trip. Only f32 buffers can be chained (the
    /// line and AO kernels are f32): an f64 estimator is refused.
    pub fn device_outputs(&self) -> Result<DeviceOutputs<'_>> {
        if self.opts.precision != Precision::F32 {
            return Err(Error::InvalidArgument(
                "device chaining needs f32 precision (this curvature estimator runs f64; \
                 use --precision f32, or read the field back)"
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

    /// One device real (f32 or f64 bytes, host byte order) as f64.
    fn real_at(&self, b: &[u8]) -> f64 {
        match self.opts.precision {
            Precision::F32 => f64::from(f32::from_ne_bytes(b.try_into().expect("4 bytes"))),
            Precision::F64 => f64::from_ne_bytes(b.try_into().expect("8 bytes")),
        }
    }

    /// Device reals as f64, in one pass with one allocation (a 2M-vertex
    /// read-back is ~300 MB of f64s, and every intermediate vector costs its
    /// page faults).
    fn to_f64(&self, bytes: &[u8]) -> Vec<f64> {
        self.rows::<1>(bytes).map(|[x]| x).collect()
    }

    fn to_vecs<const N: usize>(&self, bytes: &[u8]) -> Vec<[f64; N]> {
        self.rows(bytes).collect()
    }

    /// The values of a buffer of `N` device reals per vertex, vertex by
    /// vertex, as f64.
    fn rows<'b, const N: usize>(&'b self, bytes: &'b [u8]) -> impl Iterator<Item = [f64; N]> + 'b {
        let r = self.real;
        bytes
            .chunks_exact(N * r)
            .map(move |c| std::array::from_fn(|i| self.real_at(&c[i * r..(i + 1) * r])))
    }

    /// Reads the raw device state (normalized coordinates): the seven
    /// buffers one after another through one staging buffer, each converted
    /// to f64 as it arrives. One staging buffer rather than seven: on a
    /// 2M-vertex mesh the seven would be 150 MB of fresh pages whose first
    /// touch costs more than the copies (0.2–1.5 s in a sandboxed VM).
    pub fn read_intermediate(&self) -> Result<Intermediate> {
        let mut st = vec![0u8; 4 * self.nv * self.real];
        Ok(Intermediate {
            normals: self.to_vecs::<3>(self.fetch(&mut st, &self.nrm, 3)?),
            areas: self.to_f64(self.fetch(&mut st, &self.area, 1)?),
            pd1: self.to_vecs::<3>(self.fetch(&mut st, &self.pd1, 3)?),
            pd2: self.to_vecs::<3>(self.fetch(&mut st, &self.pd2, 3)?),
            tensor: self.to_vecs::<3>(self.fetch(&mut st, &self.tens, 3)?),
            k: self.to_vecs::<2>(self.fetch(&mut st, &self.kk, 2)?),
            dk: self.to_vecs::<4>(self.fetch(&mut st, &self.dk, 4)?),
        })
    }

    /// Reads the first `n` reals per vertex of `buf` into `staging`.
    fn fetch<'s>(&self, staging: &'s mut [u8], buf: &Buffer<u8>, n: usize) -> Result<&'s [u8]> {
        let out = &mut staging[..n * self.nv * self.real];
        self.gpu.read(buf, out)?;
        Ok(out)
    }

    /// Reads the results of the last full run, mapped back to the pose's
    /// own coordinates.
    pub fn read(&self) -> Result<CurvatureField> {
        self.read_placed(None)
    }

    /// [`CurvatureEstimator::read`] with vertex `v`'s values stored at index
    /// `place[v]` of the field (a permutation, e.g. back to an input order
    /// the mesh was renumbered from). Each buffer is converted, scaled back
    /// and placed as it arrives, in one pass into the field's own vectors:
    /// on a 2M-vertex mesh every extra copy of the field is 300 MB of fresh
    /// pages, whose first touch costs more than the conversion.
    ///
    /// # Errors
    ///
    /// [`Error::InvalidArgument`] when `place` is not a permutation of the
    /// vertices; OpenCL errors of the reads.
    pub fn read_placed(&self, place: Option<&[u32]>) -> Result<CurvatureField> {
        let n = self.nv;
        check_place("read_placed", place, n)?;
        let at = |v: usize| place.map_or(v, |p| p[v] as usize);
        let s = self.norm.scale;
        let mut f = CurvatureField::zeros(n);
        let mut st = vec![0u8; 4 * n * self.real];
        // The scalings are those of `Normalization::unapply`, operation for
        // operation, so that the values are the same bits.
        for (v, x) in self
            .rows::<3>(self.fetch(&mut st, &self.nrm, 3)?)
            .enumerate()
        {
            f.normals[at(v)] = x;
        }
        for (v, [a]) in self
            .rows::<1>(self.fetch(&mut st, &self.area, 1)?)
            .enumerate()
        {
            f.areas[at(v)] = a * (s * s);
        }
        for (v, x) in self
            .rows::<3>(self.fetch(&mut st, &self.pd1, 3)?)
            .enumerate()
        {
            f.d1[at(v)] = x;
        }
        for (v, x) in self
            .rows::<3>(self.fetch(&mut st, &self.pd2, 3)?)
            .enumerate()
        {
            f.d2[at(v)] = x;
        }
        for (v, [a, b]) in self
            .rows::<2>(self.fetch(&mut st, &self.kk, 2)?)
            .enumerate()
        {
            let i = at(v);
            f.k1[i] = a / s;
            f.k2[i] = b / s;
        }
        if self.opts.dcurv {
            for (v, d) in self
                .rows::<4>(self.fetch(&mut st, &self.dk, 4)?)
                .enumerate()
            {
                f.dk[at(v)] = d.map(|d| d / (s * s));
            }
        }
        Ok(f)
    }

    /// The results of the last full run read where they lie, with no copy
    /// of the field: the device buffers mapped (on CPU runtimes the device's
    /// memory is the host's, so mapping copies nothing), each vertex's values
    /// converted and scaled back when asked for, with the same operations
    /// and so the same bits as [`CurvatureEstimator::read_placed`] with the
    /// same `place`. For writing a large field straight to a file: on a
    /// 2M-vertex mesh the field is 256 MB of fresh pages whose first touch
    /// costs more than the conversions.
    ///
    /// # Errors
    ///
    /// As [`CurvatureEstimator::read_placed`]; OpenCL errors of the maps.
    pub fn mapped(&self, place: Option<&[u32]>) -> Result<MappedField<'_>> {
        let n = self.nv;
        check_place("mapped", place, n)?;
        let device_of = place.map(|p| {
            let mut d = vec![0u32; n];
            for (v, &i) in p.iter().enumerate() {
                d[i as usize] = v as u32;
            }
            d
        });
        let map = |b, comps: usize| self.map_reals(b, comps);
        Ok(MappedField {
            n,
            precision: self.opts.precision,
            scale: self.norm.scale,
            device_of,
            nrm: map(&self.nrm, 3)?,
            area: map(&self.area, 1)?,
            pd1: map(&self.pd1, 3)?,
            pd2: map(&self.pd2, 3)?,
            kk: map(&self.kk, 2)?,
            dk: if self.opts.dcurv {
                Some(map(&self.dk, 4)?)
            } else {
                None
            },
        })
    }

    /// Maps the first `comps` reals per vertex of `b` for reading.
    fn map_reals<'a>(&'a self, b: &'a Buffer<u8>, comps: usize) -> Result<Mapped<'a, u8>> {
        self.gpu.map_read(b, comps * self.nv * self.real)
    }
}

/// Refuses a `place` that is not a permutation of the `n` vertices.
fn check_place(what: &str, place: Option<&[u32]>, n: usize) -> Result<()> {
    if let Some(p) = place {
        let mut seen = vec![false; n];
        let permutation = p.len() == n
            && p.iter()
                .all(|&i| (i as usize) < n && !std::mem::replace(&mut seen[i as usize], true));
        if !permutation {
            return Err(Error::InvalidArgument(format!(
                "{what}: {} places are not a permutation of the {n} vertices",
                p.len()
            )));
        }
    }
    Ok(())
}

/// The results of a run read in place from the device buffers
/// ([`CurvatureEstimator::mapped`]); the buffers stay mapped, and the
/// estimator borrowed, while it lives.
pub struct MappedField<'a> {
    n: usize,
    precision: Precision,
    scale: f64,
    /// For each vertex of the field's order, the device's vertex.
    device_of: Option<Vec<u32>>,
    nrm: Mapped<'a, u8>,
    area: Mapped<'a, u8>,
    pd1: Mapped<'a, u8>,
    pd2: Mapped<'a, u8>,
    kk: Mapped<'a, u8>,
    dk: Option<Mapped<'a, u8>>,
}

impl MappedField<'_> {
    /// Number of vertices.
    pub fn len(&self) -> usize {
        self.n
    }

    /// True when there are no vertices.
    pub fn is_empty(&self) -> bool {
        self.n == 0
    }

    /// The values of vertex `i` (below [`MappedField::len`]) in the field's
    /// order, in the pose's own coordinates: the scalings of
    /// [`CurvatureEstimator::read_placed`], operation for operation.
    pub fn vertex(&self, i: usize) -> VertexCurvature {
        let v = self.device_of.as_ref().map_or(i, |d| d[i] as usize);
        match self.precision {
            Precision::F32 => self.vertex_as::<f32>(v),
            Precision::F64 => self.vertex_as::<f64>(v),
        }
    }

    /// [`MappedField::vertex`] of device vertex `v`, the buffers holding
    /// reals of type `R`: each buffer's slice for the vertex cut once, its
    /// reals read unaligned (the maps' pointers are only known to be byte
    /// aligned), so a vertex costs a few bounds checks, not one per value.
    #[inline]
    fn vertex_as<R: bytemuck::Pod + Into<f64>>(&self, v: usize) -> VertexCurvature {
        fn reals<R: bytemuck::Pod + Into<f64>, const N: usize>(b: &[u8], v: usize) -> [f64; N] {
            let w = std::mem::size_of::<R>();
            let b = &b[N * w * v..N * w * (v + 1)];
            std::array::from_fn(|c| {
                bytemuck::pod_read_unaligned::<R>(&b[c * w..(c + 1) * w]).into()
            })
        }
        let s = self.scale;
        let [area] = reals::<R, 1>(&self.area, v);
        let [k1, k2] = reals::<R, 2>(&self.kk, v);
        VertexCurvature {
            normal: reals::<R, 3>(&self.nrm, v),
            area: area * (s * s),
            k1: k1 / s,
            k2: k2 / s,
            d1: reals::<R, 3>(&self.pd1, v),
            d2: reals::<R, 3>(&self.pd2, v),
            dk: self
                .dk
                .as_ref()
                .map_or([0.0; 4], |b| reals::<R, 4>(b, v).map(|d| d / (s * s))),
        }
    }
}

/// What [`build_kernels`] did for one variant.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct KernelBuild {
    /// The variant: accumulation, precision and least squares by their
    /// command-line names (`gather f32 exact`).
    pub variant: String,
    /// How its program was obtained (`hit`: it was built already) and
    /// whether it was saved.
    pub program: crate::gpu::ProgramBuild,
    /// Seconds of getting the program and running it once.
    pub build_s: f64,
    /// Seconds of saving it.
    pub save_s: f64,
}

/// Builds the curvature program of each variant in `variants` (duplicates
/// once), runs it once ([`CurvatureEstimator::warm_up`]) and saves it into
/// shapecue's kernel cache, on every runtime (PoCL included:
/// [`Gpu::save_every_build`], which stays set on `gpu`, so give it a `Gpu`
/// of its own). A variant already in the cache is loaded, not rebuilt.
/// `on_built` hears of each program as soon as it is done (a variant can
/// take seconds on PoCL).
///
/// # Errors
///
/// [`Error::InvalidArgument`] when the cache is off (nowhere to keep the
/// kernels), and what [`CurvatureEstimator::warm_up`] returns for a variant
/// the device cannot run (the variant is named).
pub fn build_kernels(
    gpu: &Arc<Gpu>,
    variants: &[CurvatureOptions],
    mut on_built: impl FnMut(&KernelBuild),
) -> Result<Vec<KernelBuild>> {
    if gpu.cache_folder().is_none() {
        return Err(Error::InvalidArgument(
            "the kernel cache is off (SHAPECUE_NO_CACHE is set, or neither \
             SHAPECUE_CACHE_DIR, XDG_CACHE_HOME nor HOME is), so there is \
             nowhere to keep built kernels"
                .into(),
        ));
    }
    gpu.save_every_build();
    let mut done: Vec<CurvatureOptions> = Vec::new();
    let mut out = Vec::new();
    for opts in variants {
        let opts = CurvatureOptions {
            dcurv: true,
            ..*opts
        };
        if done.contains(&opts) {
            continue;
        }
        done.push(opts);
        let variant = format!(
            "{} {} {}",
            opts.accumulate.name(),
            opts.precision.name(),
            opts.compat.name()
        );
        let known = gpu.program_builds().len();
        let t = Instant::now();
        CurvatureEstimator::warm_up(gpu, &opts).map_err(|e| match e {
            Error::DeviceUnsupported { device, what } => Error::DeviceUnsupported {
                device,
                what: format!("{what} (variant {variant})"),
            },
            e => e,
        })?;
        let build_s = t.elapsed().as_secs_f64();
        let t = Instant::now();
        gpu.persist_programs();
        let save_s = t.elapsed().as_secs_f64();
        // The build record of this variant's program (none when an earlier
        // variant here had the same program).
        if let Some(program) = gpu.program_builds().get(known).cloned() {
            let b = KernelBuild {
                variant,
                program,
                build_s,
                save_s,
            };
            on_built(&b);
            out.push(b);
        }
    }
    Ok(out)
}

/// An estimator of a whole mesh computed in the memory order `order` asks
/// for ([`crate::mesh::order`]): built, each vertex's frame seeded from the
/// face that seeds it in the input's order (so directions keep their
/// signs), and the pose uploaded. Run it through `est`; read its results in
/// the input's vertex order with [`OrderedEstimator::read`].
pub struct OrderedEstimator {
    /// The estimator, on the mesh in its computing order.
    pub est: CurvatureEstimator,
    /// The renumbering it computes in, or `None` for the input's order.
    pub order: Option<LocalityOrder>,
    /// Host ms of choosing and applying the order.
    pub reorder_ms: f64,
}

/// The host half of an [`OrderedEstimator`], which needs no device: the
/// memory order chosen for a mesh, the mesh renumbered in it and each
/// vertex's frame-seeding face. A caller can compute it while the device
/// opens ([`OrderedEstimator::with_plan`]).
pub struct OrderPlan {
    order: Option<LocalityOrder>,
    reordered: Option<crate::Mesh>,
    frame_faces: Option<Vec<i32>>,
    /// Host ms of choosing and applying the order.
    pub reorder_ms: f64,
}

impl OrderPlan {
    /// Chooses the order `order` asks for on `mesh` and applies it.
    pub fn new(mesh: &crate::Mesh, order: MeshOrder) -> OrderPlan {
        let t0 = Instant::now();
        let order = LocalityOrder::choose(mesh, order);
        let reordered = order.as_ref().map(|o| o.apply(mesh));
        let frame_faces = order.as_ref().map(|o| o.frame_faces(mesh));
        OrderPlan {
            order,
            reordered,
            frame_faces,
            reorder_ms: t0.elapsed().as_secs_f64() * 1e3,
        }
    }
}

impl OrderedEstimator {
    /// Builds the estimator of `mesh` for `opts` in the order `order` picks.
    pub fn new(
        gpu: Arc<Gpu>,
        mesh: &crate::Mesh,
        opts: CurvatureOptions,
        order: MeshOrder,
    ) -> Result<Self> {
        Self::with_plan(gpu, mesh, opts, OrderPlan::new(mesh, order))
    }

    /// Builds the estimator of `mesh` for `opts` in the order of `plan`,
    /// made for this `mesh` by [`OrderPlan::new`].
    pub fn with_plan(
        gpu: Arc<Gpu>,
        mesh: &crate::Mesh,
        opts: CurvatureOptions,
        plan: OrderPlan,
    ) -> Result<Self> {
        if let Some(o) = &plan.order
            && (o.input_vertex.len() != mesh.n_vertices() || o.input_face.len() != mesh.n_faces())
        {
            return Err(Error::InvalidArgument(format!(
                "memory order made for a mesh of {} vertices and {} faces, given one of {} and {}",
                o.input_vertex.len(),
                o.input_face.len(),
                mesh.n_vertices(),
                mesh.n_faces()
            )));
        }
        let m = plan.reordered.as_ref().unwrap_or(mesh);
        let mut est = CurvatureEstimator::new(gpu, m.n_vertices(), &m.faces, opts)?;
        if let Some(f) = &plan.frame_faces {
            est.set_frame_faces(f)?;
        }
        est.set_positions(&m.positions)?;
        Ok(OrderedEstimator {
            est,
            order: plan.order,
            reorder_ms: plan.reorder_ms,
        })
    }

    /// The results of the last full run, in the input's vertex order.
    pub fn read(&self) -> Result<CurvatureField> {
        self.est
            .read_placed(self.order.as_ref().map(|o| &o.input_vertex[..]))
    }

    /// [`OrderedEstimator::read`] without the copy: the device buffers
    /// mapped, read vertex by vertex in the input's order
    /// ([`CurvatureEstimator::mapped`]); the same values, bit for bit.
    pub fn mapped(&self) -> Result<MappedField<'_>> {
        self.est
            .mapped(self.order.as_ref().map(|o| &o.input_vertex[..]))
    }
}

/// One-shot estimation: allocate, upload, run every pass, read back (the
/// front door's `shapecue::curvature_on`). A mesh whose order is scattered
/// is computed in a Morton order for cache locality and its results are
/// mapped back ([`OrderedEstimator`], [`MeshOrder::Auto`]); the time of
/// reordering counts as topology.
pub fn estimate(
    gpu: Arc<Gpu>,
    mesh: &crate::Mesh,
    opts: CurvatureOptions,
) -> Result<crate::spec::curvature::Curvature> {
    let mut o = OrderedEstimator::new(gpu, mesh, opts, MeshOrder::Auto)?;
    let timing = o.est.run()?;
    Ok(crate::spec::curvature::Curvature {
        field: o.read()?,
        counts: o.est.counts()?,
        timing,
        topology_ms: o.reorder_ms + o.est.topology_ms(),
        device_bytes: o.est.device_bytes(),
    })
}
