//! Host wiring of `kernels/curvature.cl`: per-vertex normals, point areas,
//! principal curvatures and directions, and the curvature derivative.
//!
//! [`CurvatureEstimator`] owns every device buffer. Topology-only data (face
//! indices, owning faces, one-ring lists) is uploaded and computed once in
//! [`CurvatureEstimator::new`]; [`CurvatureEstimator::set_positions`] uploads a
//! new pose into the existing buffers and [`CurvatureEstimator::run`] reruns
//! only the position-dependent passes, so a deforming mesh costs no
//! reallocation per frame (seed 000, §3.6). The CPU twin is
//! [`crate::cpu::curvature`].

use crate::error::{Error, Result};
use crate::field::{
    Accumulate, Compat, CurvatureCounts, CurvatureField, CurvatureOptions, Normalization, Precision,
};
use crate::gpu::{Arg, Gpu, buf, event_ms, kernel_file, launch};
use opencl3::kernel::Kernel;
use opencl3::memory::Buffer;
use serde::Serialize;
use std::sync::Arc;
use std::time::Instant;

/// The passes of the stage, in execution order. `MaxFace` is topology-only.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Pass {
    /// Owning face per vertex (atomic_max); once per topology.
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

/// Kernel time of one pass in one run.
#[derive(Clone, Debug, Serialize)]
pub struct PassTime {
    /// Pass name (see [`Pass::name`]).
    pub pass: &'static str,
    /// Kernel time from OpenCL profiling events, in milliseconds.
    pub kernel_ms: f64,
}

/// Timing of one [`CurvatureEstimator::run`].
#[derive(Clone, Debug, Default, Serialize)]
pub struct RunTiming {
    /// Kernel time per pass, in execution order.
    pub passes: Vec<PassTime>,
    /// Sum of the pass kernel times.
    pub kernel_ms: f64,
    /// Host wall time from the first enqueue to the end of the last kernel.
    pub wall_ms: f64,
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
    ring_off: Option<Buffer<u32>>,
    ring: Option<Buffer<u32>>,
    pos: Buffer<u8>,
    nrm: Buffer<u8>,
    area: Buffer<u8>,
    pd1: Buffer<u8>,
    pd2: Buffer<u8>,
    tens: Buffer<u8>,
    kk: Buffer<u8>,
    dk: Buffer<u8>,
    counters: Buffer<u32>,
    device_bytes: u64,
    topology_ms: f64,
}

struct Kernels {
    clear: Kernel,
    normals_areas: Kernel,
    frames: Kernel,
    tensor: Kernel,
    principal: Kernel,
    dcurv: Kernel,
}

/// Bytes of device memory the estimator allocates for a mesh, by variant
/// (the same arithmetic as the allocations in [`CurvatureEstimator::new`]).
pub fn device_bytes_bound(nv: usize, nf: usize, opts: &CurvatureOptions) -> u64 {
    let r = real_size(opts.precision) as u64;
    let (nv, nf) = (nv.max(1) as u64, nf.max(1) as u64);
    // pos, nrm, pd1, pd2, tens: 3 reals; area: 1; kk: 2; dk: 4  → 20 reals per vertex.
    let per_vertex = 20 * r + 4; // + owner
    let per_face = 12;
    let mut b = nv * per_vertex + nf * per_face + 16;
    if opts.accumulate == Accumulate::Gather {
        b += (nv + 1) * 4 + 3 * nf * 4;
    }
    b
}

fn real_size(p: Precision) -> usize {
    match p {
        Precision::F32 => 4,
        Precision::F64 => 8,
    }
}

/// Build options of `kernels/curvature.cl` for a variant.
pub fn build_options(opts: &CurvatureOptions) -> String {
    let mut s = String::new();
    if opts.precision == Precision::F64 {
        s.push_str("-DSC_DOUBLE ");
    }
    if opts.compat == Compat::Trimesh2 {
        s.push_str("-DSC_COMPAT ");
    }
    s.trim_end().to_string()
}

/// Builds the one-ring lists: for each vertex, the (face·3 + corner) entries of
/// the faces using it, in increasing face order (CSR: offsets of length V+1).
pub fn one_rings(nv: usize, faces: &[[u32; 3]]) -> (Vec<u32>, Vec<u32>) {
    let mut off = vec![0u32; nv + 1];
    for f in faces {
        for &v in f {
            off[v as usize + 1] += 1;
        }
    }
    for i in 0..nv {
        off[i + 1] += off[i];
    }
    let mut fill = off.clone();
    let mut ring = vec![0u32; faces.len() * 3];
    for (fi, f) in faces.iter().enumerate() {
        for (c, &v) in f.iter().enumerate() {
            let slot = &mut fill[v as usize];
            ring[*slot as usize] = (fi * 3 + c) as u32;
            *slot += 1;
        }
    }
    (off, ring)
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
        if faces.is_empty() {
            return Err(Error::InvalidArgument("the mesh has no faces".into()));
        }
        if let Some((i, f)) = faces
            .iter()
            .enumerate()
            .find(|(_, f)| f.iter().any(|&v| v as usize >= n_vertices))
        {
            return Err(Error::InvalidArgument(format!(
                "face {i} {f:?} indexes past the {n_vertices} vertices"
            )));
        }
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
        let t0 = Instant::now();
        let nv = n_vertices;
        let nf = faces.len();
        let real = real_size(opts.precision);
        let file = kernel_file("curvature").expect("curvature kernels are embedded");
        let program = gpu.program(&file, &build_options(&opts))?;
        let gather = opts.accumulate == Accumulate::Gather;
        let kname = |base: &str| {
            if gather && matches!(base, "curv_normals_areas" | "curv_tensor" | "curv_dcurv") {
                format!("{base}_gather")
            } else {
                base.to_string()
            }
        };
        let k = Kernels {
            clear: gpu.kernel(&program, "curv_clear")?,
            normals_areas: gpu.kernel(&program, &kname("curv_normals_areas"))?,
            frames: gpu.kernel(&program, "curv_frames")?,
            tensor: gpu.kernel(&program, &kname("curv_tensor"))?,
            principal: gpu.kernel(&program, "curv_principal")?,
            dcurv: gpu.kernel(&program, &kname("curv_dcurv"))?,
        };
        let max_face = gpu.kernel(&program, "curv_max_face")?;

        let flat: &[u32] = bytemuck::cast_slice(faces);
        let mut faces_b = gpu.buffer::<u32>(flat.len())?;
        gpu.write(&mut faces_b, flat)?;
        let mut owner = gpu.buffer::<i32>(nv)?;
        gpu.write(&mut owner, &vec![-1i32; nv])?;
        let (ring_off, ring) = if gather {
            let (off, ring) = one_rings(nv, faces);
            let mut ob = gpu.buffer::<u32>(off.len())?;
            gpu.write(&mut ob, &off)?;
            let mut rb = gpu.buffer::<u32>(ring.len())?;
            gpu.write(&mut rb, &ring)?;
            (Some(ob), Some(rb))
        } else {
            (None, None)
        };
        let ev = launch(
            &gpu,
            &max_face,
            nf,
            &[Arg::U32(nf as u32), buf(&faces_b), buf(&owner)],
        )?;
        gpu.finish()?;
        let _ = ev;
        let rb = |n: usize| gpu.buffer::<u8>(n * real);
        let est = CurvatureEstimator {
            pos: rb(3 * nv)?,
            nrm: rb(3 * nv)?,
            area: rb(nv)?,
            pd1: rb(3 * nv)?,
            pd2: rb(3 * nv)?,
            tens: rb(3 * nv)?,
            kk: rb(2 * nv)?,
            dk: rb(4 * nv)?,
            counters: gpu.buffer::<u32>(4)?,
            device_bytes: device_bytes_bound(nv, nf, &opts),
            gpu,
            opts,
            nv,
            nf,
            real,
            norm: Normalization {
                center: [0.0; 3],
                scale: 1.0,
            },
            referenced: crate::mesh::referenced(nv, faces),
            staging: Vec::with_capacity(3 * nv * real),
            k,
            faces: faces_b,
            owner,
            ring_off,
            ring,
            topology_ms: t0.elapsed().as_secs_f64() * 1e3,
        };
        Ok(est)
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
        if let Some(i) = positions
            .iter()
            .position(|p| !p.iter().all(|c| c.is_finite()))
        {
            return Err(Error::InvalidArgument(format!(
                "vertex {i} of the pose has a non-finite coordinate"
            )));
        }
        self.norm = Normalization::of_masked(positions, Some(&self.referenced));
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
        self.gpu.write(&mut self.pos, &self.staging)
    }

    /// The normalization of the current pose.
    pub fn normalization(&self) -> Normalization {
        self.norm
    }

    /// Runs every position-dependent pass on the current pose.
    pub fn run(&mut self) -> Result<RunTiming> {
        self.run_until(Pass::Dcurv)
    }

    /// Runs the position-dependent passes up to and including `last`
    /// (the dcurv pass only if the options ask for it).
    pub fn run_until(&mut self, last: Pass) -> Result<RunTiming> {
        let g = &*self.gpu;
        let (nv, nf) = (self.nv as u32, self.nf as u32);
        let gather = self.opts.accumulate == Accumulate::Gather;
        g.write(&mut self.counters, &[0u32; 4])?;
        let t0 = Instant::now();
        let mut events = Vec::new();
        let mut go = |pass: Pass, ev: Option<opencl3::event::Event>| {
            if let Some(e) = ev {
                events.push((pass, e));
            }
        };
        let (ro, rl) = match (&self.ring_off, &self.ring) {
            (Some(o), Some(r)) => (buf(o), buf(r)),
            _ => (buf(&self.faces), buf(&self.faces)), // unused by the atomic kernels
        };
        let nvn = self.nv;
        let nfn = self.nf;
        let wanted = |p: Pass| p <= last;

        if !gather {
            go(
                Pass::Clear,
                launch(
                    g,
                    &self.k.clear,
                    nvn,
                    &[
                        Arg::U32(nv),
                        buf(&self.nrm),
                        buf(&self.area),
                        buf(&self.tens),
                        buf(&self.dk),
                    ],
                )?,
            );
        }
        if wanted(Pass::NormalsAreas) {
            let ev = if gather {
                launch(
                    g,
                    &self.k.normals_areas,
                    nvn,
                    &[
                        Arg::U32(nv),
                        buf(&self.pos),
                        buf(&self.faces),
                        ro,
                        rl,
                        buf(&self.nrm),
                        buf(&self.area),
                        buf(&self.counters),
                    ],
                )?
            } else {
                launch(
                    g,
                    &self.k.normals_areas,
                    nfn,
                    &[
                        Arg::U32(nf),
                        buf(&self.pos),
                        buf(&self.faces),
                        buf(&self.nrm),
                        buf(&self.area),
                        buf(&self.counters),
                    ],
                )?
            };
            go(Pass::NormalsAreas, ev);
        }
        if wanted(Pass::Frames) {
            go(
                Pass::Frames,
                launch(
                    g,
                    &self.k.frames,
                    nvn,
                    &[
                        Arg::U32(nv),
                        buf(&self.pos),
                        buf(&self.faces),
                        buf(&self.owner),
                        buf(&self.nrm),
                        buf(&self.area),
                        buf(&self.pd1),
                        buf(&self.pd2),
                        buf(&self.counters),
                    ],
                )?,
            );
        }
        if wanted(Pass::Tensor) {
            let ev = if gather {
                launch(
                    g,
                    &self.k.tensor,
                    nvn,
                    &[
                        Arg::U32(nv),
                        buf(&self.pos),
                        buf(&self.faces),
                        ro,
                        rl,
                        buf(&self.nrm),
                        buf(&self.area),
                        buf(&self.pd1),
                        buf(&self.pd2),
                        buf(&self.tens),
                        buf(&self.counters),
                    ],
                )?
            } else {
                launch(
                    g,
                    &self.k.tensor,
                    nfn,
                    &[
                        Arg::U32(nf),
                        buf(&self.pos),
                        buf(&self.faces),
                        buf(&self.nrm),
                        buf(&self.area),
                        buf(&self.pd1),
                        buf(&self.pd2),
                        buf(&self.tens),
                        buf(&self.counters),
                    ],
                )?
            };
            go(Pass::Tensor, ev);
        }
        if wanted(Pass::Principal) {
            go(
                Pass::Principal,
                launch(
                    g,
                    &self.k.principal,
                    nvn,
                    &[
                        Arg::U32(nv),
                        buf(&self.nrm),
                        buf(&self.tens),
                        buf(&self.pd1),
                        buf(&self.pd2),
                        buf(&self.kk),
                    ],
                )?,
            );
        }
        if wanted(Pass::Dcurv) && self.opts.dcurv {
            let ev = if gather {
                launch(
                    g,
                    &self.k.dcurv,
                    nvn,
                    &[
                        Arg::U32(nv),
                        buf(&self.pos),
                        buf(&self.faces),
                        ro,
                        rl,
                        buf(&self.area),
                        buf(&self.pd1),
                        buf(&self.pd2),
                        buf(&self.kk),
                        buf(&self.dk),
                        buf(&self.counters),
                    ],
                )?
            } else {
                launch(
                    g,
                    &self.k.dcurv,
                    nfn,
                    &[
                        Arg::U32(nf),
                        buf(&self.pos),
                        buf(&self.faces),
                        buf(&self.area),
                        buf(&self.pd1),
                        buf(&self.pd2),
                        buf(&self.kk),
                        buf(&self.dk),
                        buf(&self.counters),
                    ],
                )?
            };
            go(Pass::Dcurv, ev);
        }
        g.finish()?;
        let wall_ms = t0.elapsed().as_secs_f64() * 1e3;
        let passes: Vec<PassTime> = events
            .iter()
            .map(|(p, e)| PassTime {
                pass: p.name(),
                kernel_ms: event_ms(e),
            })
            .collect();
        let kernel_ms = passes.iter().map(|p| p.kernel_ms).sum();
        Ok(RunTiming {
            passes,
            kernel_ms,
            wall_ms,
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

    fn read_real(&self, b: &Buffer<u8>, n: usize) -> Result<Vec<f64>> {
        let mut bytes = vec![0u8; n * self.real];
        self.gpu.read(b, &mut bytes)?;
        Ok(match self.opts.precision {
            Precision::F32 => bytemuck::pod_collect_to_vec::<u8, f32>(&bytes)
                .into_iter()
                .map(f64::from)
                .collect(),
            Precision::F64 => bytemuck::pod_collect_to_vec::<u8, f64>(&bytes),
        })
    }

    fn read_vec<const N: usize>(&self, b: &Buffer<u8>) -> Result<Vec<[f64; N]>> {
        let flat = self.read_real(b, N * self.nv)?;
        Ok(flat
            .chunks_exact(N)
            .map(|c| std::array::from_fn(|i| c[i]))
            .collect())
    }

    /// Reads the raw device state (normalized coordinates).
    pub fn read_intermediate(&self) -> Result<Intermediate> {
        Ok(Intermediate {
            normals: self.read_vec::<3>(&self.nrm)?,
            areas: self.read_real(&self.area, self.nv)?,
            pd1: self.read_vec::<3>(&self.pd1)?,
            pd2: self.read_vec::<3>(&self.pd2)?,
            tensor: self.read_vec::<3>(&self.tens)?,
            k: self.read_vec::<2>(&self.kk)?,
            dk: self.read_vec::<4>(&self.dk)?,
        })
    }

    /// Reads the results of the last full run, mapped back to the pose's
    /// own coordinates.
    pub fn read(&self) -> Result<CurvatureField> {
        let i = self.read_intermediate()?;
        let mut f = CurvatureField {
            normals: i.normals,
            areas: i.areas,
            k1: i.k.iter().map(|k| k[0]).collect(),
            k2: i.k.iter().map(|k| k[1]).collect(),
            d1: i.pd1,
            d2: i.pd2,
            dk: if self.opts.dcurv {
                i.dk
            } else {
                vec![[0.0; 4]; self.nv]
            },
        };
        self.norm.unapply(&mut f);
        Ok(f)
    }
}

/// Result of [`estimate`]: the field, what was skipped and how long it took.
#[derive(Clone, Debug)]
pub struct Estimate {
    /// Per-vertex outputs.
    pub field: CurvatureField,
    /// Skip counters.
    pub counts: CurvatureCounts,
    /// Timing of the run.
    pub timing: RunTiming,
    /// Device bytes allocated.
    pub device_bytes: u64,
}

/// One-shot estimation: allocate, upload, run every pass, read back.
pub fn estimate(gpu: Arc<Gpu>, mesh: &crate::Mesh, opts: CurvatureOptions) -> Result<Estimate> {
    let mut est = CurvatureEstimator::new(gpu, mesh.n_vertices(), &mesh.faces, opts)?;
    est.set_positions(&mesh.positions)?;
    let timing = est.run()?;
    Ok(Estimate {
        field: est.read()?,
        counts: est.counts()?,
        timing,
        device_bytes: est.device_bytes(),
    })
}
