//! Host wiring of `kernels/ao.cl`: ambient occlusion from (k1, k2) at one of
//! three accuracy levels. The table of the `lut` level is built once per
//! process on the host (f64 integral) and uploaded once per stage.
//! [`AoStage::run`] takes (k1, k2) from the host; [`AoStage::run_device`]
//! reads them from a curvature estimator's device buffer (the per-frame
//! pipeline), and both leave the values on the device for [`AoStage::read`].
//! CPU twin: [`crate::cpu::ao`]; shared mode, table and directions:
//! [`crate::spec::ao`].

use crate::error::{Error, Result};
use crate::gpu::{Arg, Gpu, buf, kernel_file, launch, wait_ms};
use crate::spec::ao::AoKernel;
use crate::spec::ao::{AoMode, LUT_N, dirs};
use crate::stages::curvature::CurvatureEstimator;
use opencl3::event::Event;
use opencl3::kernel::Kernel;
use opencl3::memory::{Buffer, CL_MEM_READ_ONLY};
use std::sync::Arc;

/// Ambient occlusion on the device.
pub struct AoStage {
    gpu: Arc<Gpu>,
    kernel: Kernel,
    lut: Buffer<f32>,
    dirs: Buffer<f32>,
    k: Buffer<f32>,
    out: Buffer<f32>,
    cap: usize,
    /// Vertices of the last run (what [`AoStage::read`] may return).
    computed: usize,
}

impl AoStage {
    /// Builds the kernel and uploads the table.
    pub fn new(gpu: Arc<Gpu>) -> Result<Self> {
        let file = kernel_file("ao").expect("ao kernels are embedded");
        let p = gpu.program(&file, "")?;
        let mut lb = gpu.buffer_flags::<f32>(LUT_N * LUT_N, CL_MEM_READ_ONLY)?;
        gpu.write(&mut lb, crate::spec::ao::lut())?;
        let d = dirs();
        let mut db = gpu.buffer_flags::<f32>(d.len(), CL_MEM_READ_ONLY)?;
        gpu.write(&mut db, &d)?;
        Ok(AoStage {
            dirs: db,
            kernel: gpu.entry(&p, AoKernel::Vertex)?,
            lut: lb,
            k: gpu.buffer(2)?,
            out: gpu.buffer(1)?,
            cap: 1,
            computed: 0,
            gpu,
        })
    }

    /// AO of each vertex from its (k1, k2), hemisphere radius `radius`
    /// (world units, > 0); returns the values and the kernel ms.
    pub fn run(&mut self, k: &[[f32; 2]], radius: f32, mode: AoMode) -> Result<(Vec<f32>, f64)> {
        check_radius(radius)?;
        let n = k.len();
        self.reserve(n)?;
        self.gpu.write(&mut self.k, k.as_flattened())?;
        let ms = wait_ms(self.enqueue(buf(&self.k), n, radius, mode)?)?;
        Ok((self.read(n)?, ms))
    }

    /// AO of every vertex of the estimator's last run, without a host round
    /// trip: (k1, k2) are read from its device buffer. `radius` is in world
    /// units (> 0); the device curvatures are normalized (× scale), so the
    /// kernel gets `radius / scale` and `k·R` is the same product as in
    /// [`AoStage::run`]. The values stay on the device ([`AoStage::read`]);
    /// returns the kernel ms. Needs an f32 estimator.
    pub fn run_device(
        &mut self,
        est: &CurvatureEstimator,
        radius: f32,
        mode: AoMode,
    ) -> Result<f64> {
        let ev = self.enqueue_device(est, radius, mode)?;
        wait_ms(ev)
    }

    /// [`AoStage::run_device`] without waiting: the kernel's profiling event.
    pub(crate) fn enqueue_device(
        &mut self,
        est: &CurvatureEstimator,
        radius: f32,
        mode: AoMode,
    ) -> Result<Option<Event>> {
        check_radius(radius)?;
        let d = est.device_outputs()?;
        let r = (f64::from(radius) / d.norm.scale) as f32;
        if !(r.is_finite() && r > 0.0) {
            return Err(Error::InvalidArgument(format!(
                "AO radius {radius} over the mesh scale {} is not a positive f32",
                d.norm.scale
            )));
        }
        self.reserve(d.nv)?;
        self.enqueue(buf(d.k), d.nv, r, mode)
    }

    /// The first `n` AO values of the last run (at most the vertices it computed).
    pub fn read(&self, n: usize) -> Result<Vec<f32>> {
        if n > self.computed {
            return Err(Error::InvalidArgument(format!(
                "AO read of {n} values: the last run computed {}",
                self.computed
            )));
        }
        let mut out = vec![0f32; n];
        self.gpu.read(&self.out, &mut out)?;
        Ok(out)
    }

    /// Grows the buffers to `n` vertices.
    fn reserve(&mut self, n: usize) -> Result<()> {
        if n > self.cap {
            self.k = self.gpu.buffer(2 * n)?;
            self.out = self.gpu.buffer(n)?;
            self.cap = n;
        }
        Ok(())
    }

    /// Enqueues `ao_vertex` on `n` (k1, k2) pairs of `k` (a float buffer of
    /// at least 2n) with the curvature-space radius `radius`.
    fn enqueue(&mut self, k: Arg, n: usize, radius: f32, mode: AoMode) -> Result<Option<Event>> {
        let ev = launch(
            &self.gpu,
            &self.kernel,
            n,
            &[
                Arg::U32(n as u32),
                k,
                Arg::F32(radius),
                Arg::U32(mode.code()),
                buf(&self.lut),
                Arg::U32(LUT_N as u32),
                buf(&self.dirs),
                buf(&self.out),
            ],
        )?;
        self.computed = n;
        Ok(ev)
    }
}

fn check_radius(radius: f32) -> Result<()> {
    if radius.is_finite() && radius > 0.0 {
        Ok(())
    } else {
        Err(Error::InvalidArgument(format!(
            "AO radius must be finite and positive, got {radius}"
        )))
    }
}
