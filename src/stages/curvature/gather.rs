//! Host wiring of `kernels/curvature_gather.cl`: each one-ring pass as a
//! per-face kernel that writes its corners' contributions, then a per-vertex
//! kernel that adds the corners of its one-ring in face order, so the
//! results are the same bits on every run (`Accumulate::Gather`). The
//! one-ring lists are built once, on the host ([`crate::mesh::topology`])
//! or on GPUs by `curv_ring_count`, a scan, `curv_ring_fill` and
//! `curv_ring_order` ([`Gather::new_on_device`], the same lists), and the
//! owning faces are their last entries.

use super::{OneRing, Pass};
use crate::error::{Error, Result};
use crate::gpu::{Arg, Gpu, buf, launch};
use crate::mesh::topology::{one_rings_into, owners_from_rings};
use crate::spec::curvature::CurvKernel;
use crate::spec::curvature::{
    MAX_FACE_LANES, corner_reals_bound, corner_weights_bound, one_ring_len_bound, padded_vertices,
};
use opencl3::event::Event;
use opencl3::kernel::Kernel;
use opencl3::memory::Buffer;
use opencl3::program::Program;

/// The gather scheme's kernels.
pub(super) struct Kernels {
    /// The per-face corner kernels of the normal, tensor and derivative passes.
    face: [Kernel; 3],
    /// The per-vertex one-ring sums of the same passes.
    sums: [Kernel; 3],
}

impl Kernels {
    /// The kernels of a program built with `SC_GATHER`.
    pub(super) fn new(gpu: &Gpu, program: &Program) -> Result<Self> {
        Ok(Kernels {
            sums: [
                gpu.entry(program, CurvKernel::NormalsAreasSum)?,
                gpu.entry(program, CurvKernel::TensorSum)?,
                gpu.entry(program, CurvKernel::DcurvSum)?,
            ],
            face: [
                gpu.entry(program, CurvKernel::NormalsAreasCorners)?,
                gpu.entry(program, CurvKernel::TensorCorners)?,
                gpu.entry(program, CurvKernel::DcurvCorners)?,
            ],
        })
    }
}

/// The gather scheme's kernels and buffers: one-ring lists and corner
/// contributions.
pub(super) struct Gather {
    k: Kernels,
    ring_off: Buffer<u32>,
    ring: Buffer<u32>,
    corner: Buffer<u8>,
    /// Corner areas, then weights, of each face corner (3 reals per face).
    cw: Buffer<u8>,
}

/// Refuses a mesh of `nf` faces whose corner slots pass 32 bits.
pub(super) fn check_faces(nf: usize) -> Result<()> {
    if corner_reals_bound(nf) > u32::MAX as usize {
        return Err(Error::InvalidArgument(format!(
            "{nf} faces are more than the gather scheme's 32-bit corner slots address \
             ({} at most); use accumulate = atomic",
            u32::MAX as usize / 12 - MAX_FACE_LANES as usize
        )));
    }
    Ok(())
}

impl Gather {
    /// Builds the one-ring lists of `faces` (`nv` vertices) in the device
    /// buffers themselves (mapped: no host copy on CPU runtimes) and the
    /// owning faces, their last entries, into `owner` (whole blocks of
    /// [`MAX_FACE_LANES`] vertices, −1 in the padding), and allocates the corner buffers for reals of `real`
    /// bytes. `fills` enqueues the estimator's buffer fills once the maps
    /// are made (a blocking map waits for what the queue holds), so that
    /// they run while the lists are built.
    pub(super) fn new(
        gpu: &Gpu,
        k: Kernels,
        faces: &[[u32; 3]],
        nv: usize,
        owner: &mut Buffer<i32>,
        real: usize,
        fills: impl FnOnce() -> Result<()>,
    ) -> Result<Self> {
        let nf = faces.len();
        let nvp = padded_vertices(nv);
        let mut ring_off = gpu.buffer::<u32>(nv + 1)?;
        let ring_len = one_ring_len_bound(nf);
        let mut ring = gpu.buffer::<u32>(ring_len)?;
        gpu.write_with(&mut ring_off, nv + 1, |off| {
            gpu.write_with(&mut ring, ring_len, |ring| {
                gpu.write_with(owner, nvp, |o| {
                    fills()?;
                    one_rings_into(faces, off, ring);
                    let (o, pad) = o.split_at_mut(nv);
                    owners_from_rings(off, ring, o);
                    pad.fill(-1);
                    Ok::<(), Error>(())
                })
            })
        })????;
        Ok(Gather {
            k,
            ring_off,
            ring,
            corner: gpu.buffer::<u8>(corner_reals_bound(nf) * real)?,
            cw: gpu.buffer::<u8>(corner_weights_bound(nf) * real)?,
        })
    }

    /// As [`Gather::new`], with the one-ring lists and owners built on the
    /// device from the faces already there (`faces_b`, `nf` faces): a count
    /// per vertex, its exclusive scan, a fill in any order and a sort of each
    /// list into face order. Linear work in parallel, where the host build
    /// would write scattered entries through a mapping of device memory.
    #[allow(clippy::too_many_arguments)]
    pub(super) fn new_on_device(
        gpu: &std::sync::Arc<Gpu>,
        k: Kernels,
        program: &Program,
        faces_b: &Buffer<u32>,
        nf: usize,
        nv: usize,
        owner: &mut Buffer<i32>,
        real: usize,
        fills: impl FnOnce() -> Result<()>,
    ) -> Result<Self> {
        fills()?;
        let nvp = padded_vertices(nv);
        let mut count = gpu.buffer::<u32>(nv + 1)?;
        gpu.zero(&mut count, nv + 1)?;
        let ring_off = gpu.buffer::<u32>(nv + 1)?;
        let ring_len = one_ring_len_bound(nf);
        let mut ring = gpu.buffer::<u32>(ring_len)?;
        gpu.zero(&mut ring, ring_len)?;
        let kernel = |e| gpu.entry(program, e);
        launch(
            gpu,
            &kernel(CurvKernel::RingCount)?,
            nf,
            &[Arg::U32(nf as u32), buf(faces_b), buf(&count)],
        )?;
        // 3F corners fit u32 (check_faces): no overflow check needed.
        let scan = crate::stages::scan::Scan::new(gpu.clone())?;
        scan.enqueue(&count, &ring_off, nv + 1)?;
        gpu.zero(&mut count, nv + 1)?;
        launch(
            gpu,
            &kernel(CurvKernel::RingFill)?,
            nf,
            &[
                Arg::U32(nf as u32),
                buf(faces_b),
                buf(&ring_off),
                buf(&count),
                buf(&ring),
            ],
        )?;
        launch(
            gpu,
            &kernel(CurvKernel::RingOrder)?,
            nvp,
            &[
                Arg::U32(nv as u32),
                Arg::U32(nvp as u32),
                buf(&ring_off),
                buf(&ring),
                buf(&*owner),
            ],
        )?;
        gpu.finish()?;
        Ok(Gather {
            k,
            ring_off,
            ring,
            corner: gpu.buffer::<u8>(corner_reals_bound(nf) * real)?,
            cw: gpu.buffer::<u8>(corner_weights_bound(nf) * real)?,
        })
    }

    /// Enqueues a one-ring pass: its corner kernel (one work-item per block
    /// of `lanes` faces), then its ring sum (one work-item per vertex).
    pub(super) fn one_ring(&self, g: &Gpu, r: &OneRing) -> Result<Vec<(Pass, Event)>> {
        let mut evs = Vec::new();
        let mut a = vec![Arg::U32(r.nf as u32)];
        a.extend_from_slice(r.face_args);
        a.extend([buf(&self.corner), buf(&self.cw), r.counters]);
        let blocks = r.nf.div_ceil(r.lanes as usize);
        evs.extend(launch(g, &self.k.face[r.index()], blocks, &a)?.map(|e| (r.pass, e)));
        let mut a = vec![
            Arg::U32(r.nv as u32),
            buf(&self.ring_off),
            buf(&self.ring),
            buf(&self.corner),
        ];
        a.extend_from_slice(r.outputs);
        evs.extend(launch(g, &self.k.sums[r.index()], r.nv, &a)?.map(|e| (r.pass, e)));
        Ok(evs)
    }
}
