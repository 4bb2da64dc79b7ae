//! Host wiring of `kernels/skinning.cl`: rest positions, joints and weights
//! are uploaded once; each pose uploads only the joint matrices (16 floats
//! per joint) and runs `skin_lbs`, leaving the skinned positions on the
//! device for the curvature passes
//! ([`crate::stages::curvature::CurvatureEstimator::set_positions_device`]).
//! CPU twin: [`crate::cpu::skinning`]; buffer layout: [`crate::spec::skinning`].

use crate::error::{Error, Result};
use crate::gpu::{Arg, Gpu, buf, kernel_file, launch, wait_ms};
use crate::mesh::skinned::SkinnedMesh;
use crate::spec::skinning::SkinKernel;
use crate::spec::skinning::{INFLUENCES, MATRIX_FLOATS, matrices_len};
use opencl3::event::Event;
use opencl3::kernel::Kernel;
use opencl3::memory::{Buffer, CL_MEM_READ_ONLY};
use std::sync::Arc;

/// Skins one mesh on the device, pose after pose.
pub struct Skinner {
    gpu: Arc<Gpu>,
    kernel: Kernel,
    nv: usize,
    joints: usize,
    rest: Buffer<f32>,
    joint_ids: Buffer<u32>,
    weights: Buffer<f32>,
    mats: Buffer<f32>,
    /// Skinned positions, 3 floats per vertex.
    pub out: Buffer<f32>,
}

impl Skinner {
    /// Uploads the rest mesh, joints and weights.
    pub fn new(gpu: Arc<Gpu>, m: &SkinnedMesh) -> Result<Self> {
        let nv = m.rest.positions.len();
        let file = kernel_file("skinning").expect("skinning kernels are embedded");
        let p = gpu.program(&file, "")?;
        let rest_f: Vec<f32> = m
            .rest
            .positions
            .iter()
            .flatten()
            .map(|&c| c as f32)
            .collect();
        let mut rest = gpu.buffer_flags::<f32>(3 * nv, CL_MEM_READ_ONLY)?;
        gpu.write(&mut rest, &rest_f)?;
        let mut joint_ids = gpu.buffer_flags::<u32>(INFLUENCES * nv, CL_MEM_READ_ONLY)?;
        gpu.write(&mut joint_ids, m.joints.as_flattened())?;
        let mut weights = gpu.buffer_flags::<f32>(INFLUENCES * nv, CL_MEM_READ_ONLY)?;
        gpu.write(&mut weights, m.weights.as_flattened())?;
        let joints = m.joint_nodes.len();
        Ok(Skinner {
            kernel: gpu.entry(&p, SkinKernel::Lbs)?,
            mats: gpu.buffer_flags::<f32>(matrices_len(joints.max(1)), CL_MEM_READ_ONLY)?,
            out: gpu.buffer::<f32>(3 * nv)?,
            gpu,
            nv,
            joints,
            rest,
            joint_ids,
            weights,
        })
    }

    /// Vertices skinned.
    pub fn n_vertices(&self) -> usize {
        self.nv
    }

    /// Uploads `mats` (column-major, 16 floats per joint) and skins; returns
    /// the kernel ms.
    pub fn pose(&mut self, mats: &[f32]) -> Result<f64> {
        wait_ms(self.enqueue(mats)?)
    }

    /// [`Skinner::pose`] without waiting: the kernel's profiling event, for
    /// callers that queue more passes behind it
    /// ([`crate::stages::pipeline::PosePipeline`]).
    pub(crate) fn enqueue(&mut self, mats: &[f32]) -> Result<Option<Event>> {
        if mats.len() != matrices_len(self.joints) || mats.iter().any(|v| !v.is_finite()) {
            return Err(Error::InvalidArgument(format!(
                "pose: {} finite matrix floats expected ({MATRIX_FLOATS} × {} joints), got {}",
                matrices_len(self.joints),
                self.joints,
                mats.len()
            )));
        }
        self.gpu.write(&mut self.mats, mats)?;
        launch(
            &self.gpu,
            &self.kernel,
            self.nv,
            &[
                Arg::U32(self.nv as u32),
                buf(&self.rest),
                buf(&self.joint_ids),
                buf(&self.weights),
                buf(&self.mats),
                buf(&self.out),
            ],
        )
    }

    /// Reads the skinned positions.
    pub fn read(&self) -> Result<Vec<[f32; 3]>> {
        let mut v = vec![[0f32; 3]; self.nv];
        self.gpu.read(&self.out, v.as_flattened_mut())?;
        Ok(v)
    }
}
