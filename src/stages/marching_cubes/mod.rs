//! The isosurface pipeline on the device, one algorithm per file over the
//! same uploaded volume and case table: `soup.rs` wires
//! `kernels/marching_cubes.cl` (`mc_classify` → scan → `mc_triangles`, then
//! vertex fusion, [`crate::stages::vertex_fusion`]) and `direct.rs` wires
//! `kernels/marching_cubes_direct.cl` (direct numbering, after Flying
//! Edges); this file holds the [`Isosurfacer`] both extend. Either leaves the indexed mesh on the device (for the curvature
//! passes) until the caller reads it. CPU twin: [`crate::cpu::marching_cubes`];
//! shared case table, layout, bounds and options: [`crate::spec::marching_cubes`].
//!
//! Memory: a volume or an output that the device cannot hold is a clear
//! error naming the bytes needed.

mod direct;
mod soup;

use crate::error::{Error, Result};
use crate::gpu::{Arg, Gpu, buf, launch};
use crate::mesh::Mesh;
use crate::spec::curvature::{CurvatureOptions, Normalization};
use crate::spec::marching_cubes::McKernel;
use crate::spec::marching_cubes::{
    cell_rows, check_dims, edge_key_bits, halves_differences, table,
};
use crate::spec::timing::{Step, Timing};
use crate::spec::vertex_fusion::Fusion;
use crate::stages::curvature::CurvatureEstimator;
use crate::stages::kernel_files;
use crate::stages::scan::Scan;
use crate::stages::vertex_fusion::{Fuser, build_options};
use crate::volume::Volume;
use opencl3::kernel::Kernel;
use opencl3::memory::{Buffer, CL_MEM_READ_ONLY};
use std::sync::Arc;
use std::time::Instant;

/// Values ahead of each row's loads that CPU devices prefetch (2 KiB, 32
/// cache lines; 256 and 1024 were no better).
const CPU_PREFETCH_VALUES: usize = 512;

/// What one extraction did and how long each pass took.
#[derive(Clone, Debug, Default, serde::Serialize)]
pub struct IsoStats {
    /// The fusion variant.
    pub fusion: &'static str,
    /// The iso value.
    pub iso: f32,
    /// Voxels in the volume.
    pub voxels: usize,
    /// Triangles emitted by the cells (before fusion drops any): the soup's
    /// triangles, or those of direct numbering.
    pub soup_triangles: usize,
    /// Soup vertices (3 per triangle: vertices before fusion); 0 for direct
    /// numbering, which makes no soup.
    pub soup_vertices: usize,
    /// Direct numbering: vertices that rounded onto a grid point (iso equal
    /// to voxel values), which alone make the clean-up passes run.
    pub exact_hits: usize,
    /// Vertices after fusion.
    pub vertices: usize,
    /// Faces after fusion.
    pub faces: usize,
    /// Triangles dropped because two fused corners coincide (iso equal to voxel values).
    pub degenerate_dropped: usize,
    /// Kernel ms per step (`mc_classify`, the row scan, `mc_triangles`,
    /// `mc_iota` or the fusion steps), their sum, and the wall time of the
    /// extraction (volume already on the device).
    pub timing: Timing,
    /// Device bytes held after the extraction (volume, soup, scratch, outputs).
    pub device_bytes: u64,
}

/// Positions in voxel index space and faces, as read back from the device.
pub type IndexSpaceMesh = (Vec<[f32; 3]>, Vec<[u32; 3]>);

/// Which buffers hold the current result.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Holder {
    Soup,
    Fused,
    Direct,
}

/// Extracts isosurfaces of one volume on the device.
pub struct Isosurfacer {
    gpu: Arc<Gpu>,
    dims: [usize; 3],
    /// World units per voxel step.
    pub spacing: [f64; 3],
    /// World position of voxel (0, 0, 0).
    pub origin: [f64; 3],
    vol: Buffer<f32>,
    counts: Buffer<u8>,
    tris: Buffer<u8>,
    flat: Buffer<u8>,
    gradient: Kernel,
    scan: Scan,
    fuser: Fuser,
    soup: soup::Soup,
    direct: direct::Direct,
    result: Option<(Holder, usize, usize)>,
}

impl Isosurfacer {
    /// Uploads `vol` to the device (once) and builds the kernels. Errors if
    /// the device cannot hold the volume, naming the bytes.
    pub fn new(gpu: Arc<Gpu>, vol: &Volume) -> Result<Self> {
        Self::with_hash_mask(gpu, vol, None)
    }

    /// Like [`Isosurfacer::new`], with the position hash masked to
    /// `collide_mask` (tests: forces hash collisions; fusion stays exact).
    #[doc(hidden)]
    pub fn with_hash_mask(gpu: Arc<Gpu>, vol: &Volume, collide_mask: Option<u32>) -> Result<Self> {
        let bytes = vol.bytes();
        if bytes > gpu.info.max_alloc || bytes > gpu.info.global_mem {
            return Err(Error::DeviceUnsupported {
                device: gpu.info.name.clone(),
                what: format!(
                    "the volume needs {bytes} bytes of device memory ({}×{}×{} f32); the device \
                     allows {} bytes in one buffer and has {} bytes",
                    vol.dims[0], vol.dims[1], vol.dims[2], gpu.info.max_alloc, gpu.info.global_mem
                ),
            });
        }
        check_dims(vol.dims)?;
        let n = vol.voxel_count();
        let mut opts = build_options(collide_mask);
        if halves_differences(vol.max_finite_abs()) {
            opts.push_str(" -DSC_MC_HALVE");
        }
        if gpu.info.kind == "CPU" {
            // Software prefetch of the streamed rows (common/mc_cell.h): on
            // PoCL the row, count and triangle passes otherwise wait on memory.
            opts.push_str(&format!(" -DSC_CPU_PREFETCH={CPU_PREFETCH_VALUES}"));
        }
        let file = kernel_files::MARCHING_CUBES;
        let p = gpu.program(&file, &opts)?;
        let file = kernel_files::MARCHING_CUBES_DIRECT;
        let pd = gpu.program(&file, &opts)?;
        let mut volb = gpu.buffer_flags::<f32>(n, CL_MEM_READ_ONLY)?;
        gpu.write(&mut volb, &vol.values)?;
        let t = table();
        let mut counts = gpu.buffer_flags::<u8>(256, CL_MEM_READ_ONLY)?;
        gpu.write(&mut counts, &t.counts)?;
        let mut tris = gpu.buffer_flags::<u8>(256 * 16, CL_MEM_READ_ONLY)?;
        gpu.write(&mut tris, t.tris.as_flattened())?;
        let mut flat = gpu.buffer_flags::<u8>(256, CL_MEM_READ_ONLY)?;
        gpu.write(&mut flat, &t.flat)?;
        let rows = cell_rows(vol.dims);
        let grid_rows = vol.dims[1] * vol.dims[2];
        Ok(Isosurfacer {
            dims: vol.dims,
            spacing: vol.spacing,
            origin: vol.origin,
            vol: volb,
            counts,
            tris,
            flat,
            gradient: gpu.entry(&p, McKernel::GradientNormals)?,
            scan: Scan::new(gpu.clone())?,
            fuser: Fuser::new(gpu.clone())?,
            soup: soup::Soup::new(&gpu, &p, rows)?,
            direct: direct::Direct::new(
                &gpu,
                &pd,
                grid_rows,
                vol.values.iter().any(|v| !v.is_finite()),
            )?,
            result: None,
            gpu,
        })
    }

    /// The device.
    pub fn gpu(&self) -> &Arc<Gpu> {
        &self.gpu
    }

    /// Voxels per axis.
    pub fn dims(&self) -> [usize; 3] {
        self.dims
    }

    /// Device bytes held now.
    pub fn device_bytes(&self) -> u64 {
        let rows = cell_rows(self.dims) as u64;
        4 * (self.dims.iter().product::<usize>() as u64)
            + self.soup.device_bytes(rows)
            + self
                .direct
                .device_bytes((self.dims[1] * self.dims[2]) as u64)
            + self.fuser.device_bytes()
    }

    /// Extracts the surface `value = iso` with the given fusion; the result
    /// stays on the device (see [`Isosurfacer::read`], [`Isosurfacer::device_mesh`]).
    pub fn extract(&mut self, iso: f32, fusion: Fusion) -> Result<IsoStats> {
        if !iso.is_finite() {
            return Err(Error::InvalidArgument(format!(
                "iso value must be finite, got {iso}"
            )));
        }
        let t0 = Instant::now();
        let [nx, ny, nz] = self.dims;
        let voxels = nx * ny * nz;
        let mut st = IsoStats {
            fusion: fusion.name(),
            iso,
            voxels,
            ..Default::default()
        };
        self.result = None;
        let rows = cell_rows(self.dims);
        if rows == 0 || nx < 2 {
            st.device_bytes = self.device_bytes();
            self.result = Some((Holder::Soup, 0, 0));
            return Ok(st);
        }
        if fusion == Fusion::Edge && edge_key_bits(voxels).is_none() {
            return Err(Error::InvalidArgument(format!(
                "fusion = edge keys vertices by 4 × voxel index in 32 bits: at most 2^30 voxels, \
                 this volume has {voxels}; use fusion = direct or hash"
            )));
        }
        if fusion == Fusion::Direct {
            self.extract_direct(iso, &mut st)?;
        } else {
            self.extract_soup(iso, fusion, rows, &mut st)?;
        }
        st.timing.wall_ms = t0.elapsed().as_secs_f64() * 1e3;
        st.device_bytes = self.device_bytes();
        Ok(st)
    }

    /// The current result on the device: (positions: 3 floats per vertex in
    /// index space, faces: 3 indices each, vertex count, face count).
    pub fn device_mesh(&self) -> Option<(&Buffer<f32>, &Buffer<u32>, usize, usize)> {
        let (h, nv, nf) = self.result?;
        Some(match h {
            Holder::Soup => (&self.soup.pos.buf, &self.soup.faces.buf, nv, nf),
            Holder::Fused => (&self.fuser.out_pos.buf, &self.fuser.out_faces.buf, nv, nf),
            Holder::Direct => (&self.direct.pos.buf, &self.direct.faces.buf, nv, nf),
        })
    }

    /// Unit normals of the current result's vertices from the volume
    /// gradient (trilinear interpolation of central differences, world
    /// units), computed on the device into a new buffer of 3 floats per
    /// vertex; (0,0,0) where the gradient vanishes. CPU twin:
    /// [`crate::cpu::marching_cubes::gradient_normals`].
    pub fn gradient_normals(&self) -> Result<Buffer<f32>> {
        let Some((pos, _, nv, _)) = self.device_mesh() else {
            return Err(Error::InvalidArgument("no isosurface extracted yet".into()));
        };
        let out = self.gpu.buffer::<f32>(3 * nv)?;
        let [nx, ny, nz] = self.dims;
        launch(
            &self.gpu,
            &self.gradient,
            nv,
            &[
                Arg::U32(nv as u32),
                buf(pos),
                buf(&self.vol),
                Arg::U32(nx as u32),
                Arg::U32(ny as u32),
                Arg::U32(nz as u32),
                Arg::F32(self.spacing[0] as f32),
                Arg::F32(self.spacing[1] as f32),
                Arg::F32(self.spacing[2] as f32),
                buf(&out),
            ],
        )?;
        self.gpu.finish()?;
        Ok(out)
    }

    /// Reads the current result: positions in index space and faces.
    pub fn read_index_space(&self) -> Result<IndexSpaceMesh> {
        let Some((p, f, nv, nf)) = self.device_mesh() else {
            return Ok((Vec::new(), Vec::new()));
        };
        let mut pos = vec![[0f32; 3]; nv];
        let mut faces = vec![[0u32; 3]; nf];
        self.gpu.read(p, pos.as_flattened_mut())?;
        self.gpu.read(f, faces.as_flattened_mut())?;
        check_faces(&faces, nv)?;
        Ok((pos, faces))
    }

    /// Reads the current result as a mesh in world coordinates
    /// (origin + spacing ⊙ p, in f64).
    pub fn read(&self) -> Result<Mesh> {
        let (pos, faces) = self.read_index_space()?;
        Ok(self.world_mesh(&pos, faces))
    }

    /// A mesh in world coordinates (origin + spacing ⊙ p, in f64) from
    /// index-space positions read with [`Isosurfacer::read_index_space`].
    pub fn world_mesh(&self, pos: &[[f32; 3]], faces: Vec<[u32; 3]>) -> Mesh {
        Mesh {
            positions: pos
                .iter()
                .map(|p| std::array::from_fn(|i| self.origin[i] + self.spacing[i] * p[i] as f64))
                .collect(),
            faces,
            normals: None,
        }
    }
}

/// Adds the kernel time of `step` from its launch's event, if it launched.
fn add_event(st: &mut IsoStats, step: Step, e: &Option<opencl3::event::Event>) {
    if let Some(e) = e {
        st.timing.add(step, crate::gpu::event_ms(e));
    }
}

/// Every corner of `faces` names one of the `nv` vertices; else the device's
/// mesh is refused before anything writes, draws or indexes it.
fn check_faces(faces: &[[u32; 3]], nv: usize) -> Result<()> {
    match faces
        .iter()
        .enumerate()
        .find(|(_, f)| f.iter().any(|&v| v as usize >= nv))
    {
        None => Ok(()),
        Some((i, f)) => Err(Error::DeviceResult {
            what: "isosurface".into(),
            detail: format!(
                "face {i} has corners {}, {}, {} but the mesh has {nv} vertices",
                f[0], f[1], f[2]
            ),
        }),
    }
}

use crate::spec::marching_cubes::IsoNormals;

/// Curvature of the current isosurface, computed without a host round trip:
/// the fused faces and positions are copied device to device into a
/// [`crate::stages::curvature::CurvatureEstimator`] (atomic accumulation),
/// positions mapped to world units and normalized on the device, vertex
/// normals from the mesh or the volume gradient. Returns the estimator after
/// its run (read the field with its `read`) and the run's timing.
pub fn curvature(
    iso: &Isosurfacer,
    opts: CurvatureOptions,
    normals: IsoNormals,
) -> Result<(CurvatureEstimator, Timing)> {
    let Some((pos, faces, nv, nf)) = iso.device_mesh() else {
        return Err(Error::InvalidArgument("no isosurface extracted yet".into()));
    };
    let mut est = CurvatureEstimator::from_device(iso.gpu.clone(), nv, faces, nf, opts)?;
    // Normalize by the volume's box: centre and half diagonal (world units).
    let d = iso.dims;
    let center: [f64; 3] =
        std::array::from_fn(|i| iso.origin[i] + 0.5 * iso.spacing[i] * (d[i] as f64 - 1.0));
    let half = (0..3)
        .map(|i| (0.5 * iso.spacing[i] * (d[i] as f64 - 1.0)).powi(2))
        .sum::<f64>()
        .sqrt();
    let norm = Normalization {
        center,
        scale: if half > 0.0 { half } else { 1.0 },
    };
    est.set_positions_device(pos, iso.spacing, iso.origin, norm)?;
    if normals == IsoNormals::Gradient {
        est.set_normal_override(Some(iso.gradient_normals()?));
    }
    let timing = est.run()?;
    Ok((est, timing))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_face_naming_a_missing_vertex_is_refused_with_its_number() {
        assert!(check_faces(&[[0, 1, 2], [2, 1, 3]], 4).is_ok());
        let e = check_faces(&[[0, 1, 2], [2, 1, 4]], 4).unwrap_err();
        assert_eq!(
            e.to_string(),
            "the OpenCL device returned an inconsistent isosurface: \
             face 1 has corners 2, 1, 4 but the mesh has 4 vertices"
        );
        assert!(check_faces(&[], 0).is_ok());
    }
}
