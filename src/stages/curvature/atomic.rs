//! Host wiring of `kernels/curvature_atomic.cl`: the one-ring passes as float
//! atomic adds from each face to its three vertices (Griffin et al. 2012,
//! §3.6), in compare-and-swap loops or the device's own float atomic adds
//! (`Accumulate::Atomic`, `Accumulate::AtomicNative`). The owning faces come
//! from `curv_max_face` on the device, so a mesh that lives on the device
//! needs no host copy; the sums are zeroed by `curv_clear` before each run
//! and come in no fixed order.

use super::{OneRing, Pass};
use crate::error::Result;
use crate::gpu::{Arg, Gpu, buf, launch};
use crate::spec::curvature::CurvKernel;
use opencl3::event::Event;
use opencl3::kernel::Kernel;
use opencl3::memory::Buffer;
use opencl3::program::Program;

/// The atomic schemes' kernels.
pub(super) struct Kernels {
    /// Zeroes the accumulators (normals, areas, tensors, derivatives).
    clear: Kernel,
    /// The per-face kernels of the normal, tensor and derivative passes.
    face: [Kernel; 3],
}

impl Kernels {
    /// The kernels of a program built without `SC_GATHER`.
    pub(super) fn new(gpu: &Gpu, program: &Program) -> Result<Self> {
        Ok(Kernels {
            clear: gpu.entry(program, CurvKernel::Clear)?,
            face: [
                gpu.entry(program, CurvKernel::NormalsAreas)?,
                gpu.entry(program, CurvKernel::Tensor)?,
                gpu.entry(program, CurvKernel::Dcurv)?,
            ],
        })
    }

    /// Zeroes the accumulators `[nrm, area, tens, dk]` of `nv` vertices.
    pub(super) fn clear(&self, g: &Gpu, nv: usize, sums: [Arg; 4]) -> Result<Option<Event>> {
        let [nrm, area, tens, dk] = sums;
        launch(
            g,
            &self.clear,
            nv,
            &[Arg::U32(nv as u32), nrm, area, tens, dk],
        )
    }

    /// Enqueues a one-ring pass: its per-face kernel adds each face's
    /// corners to their vertices' sums (one work-item per block of `lanes`
    /// faces).
    pub(super) fn one_ring(&self, g: &Gpu, r: &OneRing) -> Result<Vec<(Pass, Event)>> {
        let mut a = vec![Arg::U32(r.nf as u32)];
        a.extend_from_slice(r.face_args);
        a.extend_from_slice(r.outputs);
        a.push(r.counters);
        let blocks = r.nf.div_ceil(r.lanes as usize);
        Ok(launch(g, &self.face[r.index()], blocks, &a)?
            .map(|e| (r.pass, e))
            .into_iter()
            .collect())
    }
}

/// Fills `owner` (`nvp` entries) with each vertex's owning face, the largest
/// face id using it (−1 for none), with `curv_max_face` on the device.
pub(super) fn owners(
    gpu: &Gpu,
    program: &Program,
    faces: &Buffer<u32>,
    nf: usize,
    owner: &mut Buffer<i32>,
    nvp: usize,
) -> Result<()> {
    let max_face = gpu.entry(program, CurvKernel::MaxFace)?;
    gpu.write(owner, &vec![-1i32; nvp])?;
    launch(
        gpu,
        &max_face,
        nf,
        &[Arg::U32(nf as u32), buf(faces), buf(owner)],
    )?;
    Ok(())
}
