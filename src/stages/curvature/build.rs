//! Building the curvature program for a variant: the device checks, the
//! build options, the kernels of the common passes and of the accumulation
//! scheme; [`build_kernels`] builds and saves variants ahead of use; with
//! the program built, a mesh's per-vertex buffers and its scheme's
//! topology-only data ([`topology`]).

use super::{CurvatureEstimator, Faces, Scheme, atomic, gather, rings_on_device};
use crate::error::{Error, Result};
use crate::gpu::Gpu;
use crate::spec::curvature::CurvKernel;
use crate::spec::curvature::{
    Accumulate, Compat, CurvatureOptions, Lanes, Precision, padded_vertices,
};
use crate::spec::timing::Timing;
use crate::stages::kernel_files;
use opencl3::kernel::Kernel;
use opencl3::memory::Buffer;
use opencl3::program::Program;
use std::sync::Arc;
use std::time::Instant;

/// The kernels of the passes both schemes share.
pub(super) struct Kernels {
    pub(super) frames: Kernel,
    pub(super) count_empty: Kernel,
    pub(super) principal: Kernel,
    /// Positions from a device buffer of index-space floats (isosurfaces).
    pub(super) load_positions: Kernel,
    /// Given unit normals replace the accumulated ones (isosurfaces).
    pub(super) override_normals: Kernel,
    /// Faces per work-item of the per-face kernels, and vertices per
    /// work-item of the frame and principal kernels: `SC_LANES` of the build.
    pub(super) lanes: u32,
}

/// The kernels of the accumulation scheme a program was built for.
pub(super) enum SchemeKernels {
    /// `kernels/curvature_atomic.cl` (either atomic scheme).
    Atomic(atomic::Kernels),
    /// `kernels/curvature_gather.cl`.
    Gather(gather::Kernels),
}

/// A program built for one variant, its kernels, and when the estimator's
/// set-up began (what [`CurvatureEstimator::with_faces`] needs of a build).
pub(super) struct Built {
    pub(super) k: Kernels,
    pub(super) scheme: SchemeKernels,
    pub(super) program: Arc<Program>,
    /// When the set-up began (the build is part of the topology time).
    pub(super) t0: Instant,
    /// Wall ms of getting the program and creating the kernels.
    pub(super) build_ms: f64,
}

/// How a device adds floats atomically for `--accumulate atomic-native`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum NativeAdds {
    /// `cl_ext_float_atomics` (OpenCL C 3.0 `atomic_fetch_add_explicit`).
    Extension,
    /// Inline PTX `red.global.add` on NVIDIA's CUDA platform, the paper's
    /// CUDA `atomicAdd`, where the extension is missing.
    Ptx,
}

/// Build options of `kernels/curvature.cl` for a variant, with `lanes` faces
/// per work-item in the per-face kernels; `pair_adds`: the compare-and-swap
/// scheme in f32 adds two adjacent floats in one 64-bit compare-and-swap
/// where it can (the device has `cl_khr_int64_base_atomics`); `native`: how
/// `atomic-native` adds.
pub fn build_options(
    opts: &CurvatureOptions,
    lanes: u32,
    pair_adds: bool,
    native: NativeAdds,
) -> String {
    let mut s = String::new();
    if pair_adds && opts.accumulate == Accumulate::Atomic && opts.precision == Precision::F32 {
        s.push_str("-DSC_PAIR_ADDS ");
    }
    if opts.accumulate == Accumulate::Gather {
        // kernels/curvature.cl then includes the gather scheme's kernels
        // (kernels/curvature_gather.cl), not the atomic ones.
        s.push_str("-DSC_GATHER ");
    }
    if lanes > 1 {
        s.push_str(&format!("-DSC_LANES={lanes} "));
    }
    match (opts.accumulate, native) {
        // atomic_fetch_add_explicit on atomic_float needs OpenCL C 2.0 or later
        (Accumulate::AtomicNative, NativeAdds::Extension) => {
            s.push_str("-cl-std=CL3.0 -DSC_NATIVE_ATOMICS ")
        }
        (Accumulate::AtomicNative, NativeAdds::Ptx) => s.push_str("-DSC_PTX_ATOMICS "),
        _ => {}
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

    /// Gets the program for `opts` built into `gpu` and creates its kernels.
    pub(super) fn build(gpu: &Arc<Gpu>, opts: &CurvatureOptions) -> Result<Built> {
        let t0 = Instant::now();
        if opts.precision == Precision::F64 {
            if !gpu.info.fp64 {
                return Err(Error::DeviceUnsupported {
                    device: gpu.info.name.clone(),
                    what: "precision = f64 needs cl_khr_fp64".into(),
                });
            }
            if opts.accumulate == Accumulate::Atomic && !gpu.info.int64_atomics {
                return Err(Error::DeviceUnsupported {
                    device: gpu.info.name.clone(),
                    what: "f64 atomic accumulation needs cl_khr_int64_base_atomics; \
                           use accumulate = gather"
                        .into(),
                });
            }
        }
        let extension = match opts.precision {
            Precision::F32 => gpu.info.float_atomics,
            Precision::F64 => gpu.info.double_atomics,
        };
        let native_adds = if extension {
            NativeAdds::Extension
        } else {
            NativeAdds::Ptx
        };
        if opts.accumulate == Accumulate::AtomicNative && !extension && !gpu.info.ptx {
            return Err(Error::DeviceUnsupported {
                device: gpu.info.name.clone(),
                what: format!(
                    "accumulate = atomic-native needs native {} float atomic adds \
                     (cl_ext_float_atomics, or NVIDIA's CUDA platform for inline PTX); \
                     use accumulate = atomic or gather",
                    opts.precision.name()
                ),
            });
        }
        if let Lanes::Fixed(n) = opts.lanes
            && !matches!(n, 1 | 2 | 4 | 8 | 16)
        {
            return Err(Error::InvalidArgument(format!(
                "face lanes must be 1, 2, 4, 8 or 16 (or auto: by device type), not {n}"
            )));
        }
        let native = match opts.precision {
            Precision::F32 => gpu.info.native_float_width,
            Precision::F64 => gpu.info.native_double_width,
        };
        let lanes = crate::spec::curvature::face_lanes_for(opts.lanes, &gpu.info.kind, native);
        let file = kernel_files::CURVATURE;
        let pair_adds = gpu.info.int64_atomics;
        let program = gpu.program(&file, &build_options(opts, lanes, pair_adds, native_adds))?;
        let scheme = if opts.accumulate == Accumulate::Gather {
            SchemeKernels::Gather(gather::Kernels::new(gpu, &program)?)
        } else {
            SchemeKernels::Atomic(atomic::Kernels::new(gpu, &program)?)
        };
        let k = Kernels {
            frames: gpu.entry(&program, CurvKernel::Frames)?,
            count_empty: gpu.entry(&program, CurvKernel::CountEmpty)?,
            principal: gpu.entry(&program, CurvKernel::Principal)?,
            load_positions: gpu.entry(&program, CurvKernel::LoadPositions)?,
            override_normals: gpu.entry(&program, CurvKernel::OverrideNormals)?,
            lanes,
        };
        Ok(Built {
            k,
            scheme,
            program,
            t0,
            build_ms: t0.elapsed().as_secs_f64() * 1e3,
        })
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

/// Reals per vertex of pos, nrm, area, pd1, pd2, tens, kk, dk.
const REALS: [usize; 8] = [3, 3, 1, 3, 3, 3, 2, 4];

/// Reals of per-vertex buffer `i` of `REALS` (`n` per vertex) for `nvp`
/// padded vertices. The positions have one real more: the normal pass
/// with lanes loads each vertex's x y z as 4 reals (ld_pos in
/// kernels/common/curvature_lanes.h).
fn vertex_reals(i: usize, n: usize, nvp: usize) -> usize {
    n * nvp + usize::from(i == 0)
}

/// The per-vertex buffers of `REALS` for `nvp` padded vertices of `real`
/// bytes per real.
pub(super) fn vertex_buffers(gpu: &Gpu, nvp: usize, real: usize) -> Result<Vec<Buffer<u8>>> {
    REALS
        .iter()
        .enumerate()
        .map(|(i, &n)| gpu.buffer::<u8>(vertex_reals(i, n, nvp) * real))
        .collect()
}

/// Zeroes the per-vertex buffers (enqueued, then flushed). Zeroed once: a
/// partial run (normals only, for contours) leaves the curvature buffers
/// unwritten, and later stages reading them through
/// [`CurvatureEstimator::device_outputs`] must see finite values.
fn zero_vertex_buffers(gpu: &Gpu, bufs: &mut [Buffer<u8>], nvp: usize, real: usize) -> Result<()> {
    for (i, (b, n)) in bufs.iter_mut().zip(REALS).enumerate() {
        gpu.zero(b, vertex_reals(i, n, nvp) * real)?;
    }
    gpu.flush()
}

/// The topology-only data of the scheme's kernels for `faces` (one-rings
/// for gather, the owning faces into `owner` either way), with the
/// per-vertex buffers `bufs` zeroed beside it.
pub(super) fn topology(
    gpu: &Arc<Gpu>,
    scheme: SchemeKernels,
    program: &Program,
    faces: &Faces<'_>,
    owner: &mut Buffer<i32>,
    bufs: &mut [Buffer<u8>],
    real: usize,
) -> Result<Scheme> {
    let (nv, nf) = (faces.nv, faces.nf);
    let nvp = padded_vertices(nv);
    // The fills are enqueued (no host zeros) and run on the device
    // beside the host's work below; the one `finish` after it waits
    // for them. On a CPU device they are also the first touch of the
    // buffers' pages, which then costs the host nothing.
    Ok(match scheme {
        SchemeKernels::Gather(gk) => {
            let fills = || zero_vertex_buffers(gpu, bufs, nvp, real);
            if rings_on_device(gpu) {
                let fb = &faces.buffer;
                Scheme::Gather(gather::Gather::new_on_device(
                    gpu, gk, program, fb, nf, nv, owner, real, fills,
                )?)
            } else {
                let host = faces.host.unwrap_or(&[]);
                Scheme::Gather(gather::Gather::new(gpu, gk, host, nv, owner, real, fills)?)
            }
        }
        SchemeKernels::Atomic(ak) => {
            zero_vertex_buffers(gpu, bufs, nvp, real)?;
            atomic::owners(gpu, program, &faces.buffer, nf, owner, nvp)?;
            Scheme::Atomic(ak)
        }
    })
}
