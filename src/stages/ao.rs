//! Host wiring of `kernels/ao.cl`: ambient occlusion from (k1, k2) at one of
//! three accuracy levels. The table of the `lut` level is built once per
//! process on the host (f64 integral) and uploaded once per stage.
//! CPU twin: [`crate::cpu::ao`].

use crate::cpu::ao::{AoMode, LUT_N, build_lut, dirs};
use crate::error::{Error, Result};
use crate::gpu::{Arg, Gpu, buf, event_ms, kernel_file, launch};
use opencl3::kernel::Kernel;
use opencl3::memory::{Buffer, CL_MEM_READ_ONLY};
use std::sync::{Arc, OnceLock};

/// The `lut` level's table (built on first use).
pub fn lut() -> &'static [f32] {
    static L: OnceLock<Vec<f32>> = OnceLock::new();
    L.get_or_init(|| build_lut(LUT_N))
}

/// Ambient occlusion on the device.
pub struct AoStage {
    gpu: Arc<Gpu>,
    kernel: Kernel,
    lut: Buffer<f32>,
    dirs: Buffer<f32>,
    k: Buffer<f32>,
    out: Buffer<f32>,
    cap: usize,
}

impl AoStage {
    /// Builds the kernel and uploads the table.
    pub fn new(gpu: Arc<Gpu>) -> Result<Self> {
        let file = kernel_file("ao").expect("ao kernels are embedded");
        let p = gpu.program(&file, "")?;
        let mut lb = gpu.buffer_flags::<f32>(LUT_N * LUT_N, CL_MEM_READ_ONLY)?;
        gpu.write(&mut lb, lut())?;
        let d = dirs();
        let mut db = gpu.buffer_flags::<f32>(d.len(), CL_MEM_READ_ONLY)?;
        gpu.write(&mut db, &d)?;
        Ok(AoStage {
            dirs: db,
            kernel: gpu.kernel(&p, "ao_vertex")?,
            lut: lb,
            k: gpu.buffer(2)?,
            out: gpu.buffer(1)?,
            cap: 1,
            gpu,
        })
    }

    /// AO of each vertex from its (k1, k2), hemisphere radius `radius`
    /// (world units, > 0); returns the values and the kernel ms.
    pub fn run(&mut self, k: &[[f32; 2]], radius: f32, mode: AoMode) -> Result<(Vec<f32>, f64)> {
        if !(radius.is_finite() && radius > 0.0) {
            return Err(Error::InvalidArgument(format!(
                "AO radius must be finite and positive, got {radius}"
            )));
        }
        let n = k.len();
        if n > self.cap {
            self.k = self.gpu.buffer(2 * n)?;
            self.out = self.gpu.buffer(n)?;
            self.cap = n;
        }
        self.gpu.write(&mut self.k, k.as_flattened())?;
        let ev = launch(
            &self.gpu,
            &self.kernel,
            n,
            &[
                Arg::U32(n as u32),
                buf(&self.k),
                Arg::F32(radius),
                Arg::U32(mode.code()),
                buf(&self.lut),
                Arg::U32(LUT_N as u32),
                buf(&self.dirs),
                buf(&self.out),
            ],
        )?;
        let mut out = vec![0f32; n];
        self.gpu.read(&self.out, &mut out)?;
        Ok((out, ev.as_ref().map(event_ms).unwrap_or(0.0)))
    }
}
