//! Host wiring of `kernels/mesh_sdf.cl`: a triangle mesh to a signed
//! distance field (negative inside, world units, on the grid of
//! [`crate::spec::mesh_sdf::prepare`]), the input the curvature-directed
//! strokes need when they are given a mesh. CPU twin:
//! [`crate::cpu::mesh_sdf`], which matches it bit for bit.
//!
//! Passes: `msdf_bin_count` → scan ([`crate::stages::scan`]) →
//! `msdf_bin_fill` (the spatial grid of triangles) → `msdf_band` (exact
//! nearest triangle within the band) → `msdf_jfa` per step (jump flooding of
//! nearest-triangle candidates beyond it) → per axis `msdf_cross` +
//! `msdf_wind` (six-ray winding number, Jacobson et al. 2013) →
//! `msdf_finish`. Everything stays on the device until the field is read.
//!
//! Device memory: 7 × 4 bytes per voxel (two candidate buffers of distance
//! and triangle for the flooding ping-pong, crossings, winding, output),
//! 12 bytes per cell, 4 per list entry, 24 per vertex, 12 per triangle.

use crate::error::{Error, Result};
use crate::gpu::{Arg, COMMON_HEADERS, Gpu, KernelFile, buf, event_ms, launch};
use crate::mesh::Mesh;
use crate::spec::mesh_sdf::{
    BAND_VOXELS, CELL_VOXELS, FIX_BITS, MeshSdfOptions, PreparedMesh, prepare,
};
use crate::stages::scan::Scan;
use crate::volume::Volume;
use opencl3::event::Event;
use opencl3::kernel::Kernel;
use opencl3::memory::{Buffer, CL_MEM_READ_ONLY};
use std::sync::Arc;
use std::time::Instant;

/// The kernel file of this family.
pub const KERNELS: KernelFile = KernelFile {
    name: "kernels/mesh_sdf.cl",
    source: include_str!("../../kernels/mesh_sdf.cl"),
    headers: COMMON_HEADERS,
};

/// What one conversion did and how long each pass took.
#[derive(Clone, Debug, Default, serde::Serialize)]
pub struct MeshSdfStats {
    /// Samples along x, y, z.
    pub dims: [usize; 3],
    /// Isotropic spacing (world units).
    pub spacing: f64,
    /// World position of sample (0, 0, 0).
    pub origin: [f64; 3],
    /// Voxels.
    pub voxels: usize,
    /// Triangles used (faces minus degenerate ones).
    pub triangles: usize,
    /// Faces skipped because their (snapped) corners are collinear.
    pub degenerate_faces: usize,
    /// Entries of the spatial grid of triangles.
    pub bin_entries: u64,
    /// Jump-flooding passes (steps).
    pub jfa_passes: usize,
    /// Kernel ms: count, scan and fill of the spatial grid of triangles.
    pub bin_ms: f64,
    /// Kernel ms: msdf_band.
    pub band_ms: f64,
    /// Kernel ms: all msdf_jfa passes.
    pub jfa_ms: f64,
    /// Kernel ms: msdf_cross and msdf_wind over the three axes.
    pub sign_ms: f64,
    /// Kernel ms: msdf_finish.
    pub finish_ms: f64,
    /// Sum of the kernel times.
    pub kernel_ms: f64,
    /// Wall ms from the upload to the field read back (program build excluded).
    pub wall_ms: f64,
    /// Device bytes allocated.
    pub device_bytes: u64,
}

/// Intermediate results read back for step-by-step comparison with the CPU
/// twin ([`MeshSdf::run_traced`]).
#[derive(Clone, Debug, Default)]
pub struct MeshSdfTrace {
    /// `msdf_band`: squared distance (voxels²) and triangle per voxel.
    pub band: (Vec<f32>, Vec<u32>),
    /// After the last `msdf_jfa` pass.
    pub flooded: (Vec<f32>, Vec<u32>),
    /// Six-ray winding sum per voxel.
    pub winding: Vec<i32>,
}

/// The program and kernels of the family on one device (built once).
pub struct MeshSdf {
    gpu: Arc<Gpu>,
    scan: Scan,
    bin_count: Kernel,
    bin_fill: Kernel,
    band: Kernel,
    jfa: Kernel,
    cross: Kernel,
    wind: Kernel,
    finish: Kernel,
}

/// The options the kernels are built with: correctly rounded `f32` division
/// and square root (as in the CPU twin) and the fixed-point bits.
pub fn build_options() -> String {
    format!("-cl-fp32-correctly-rounded-divide-sqrt -DSC_FIX_BITS={FIX_BITS}")
}

/// Front door: prepares `mesh` ([`prepare`]), converts it on `gpu` and
/// returns the field as a [`Volume`] in the mesh's world coordinates
/// (negative inside) with the stats.
///
/// # Errors
///
/// Those of [`prepare`] and [`PreparedMesh::bin_entries`], device errors,
/// and a buffer larger than the device allows.
pub fn mesh_to_sdf(
    gpu: Arc<Gpu>,
    mesh: &Mesh,
    opts: &MeshSdfOptions,
) -> Result<(Volume, MeshSdfStats)> {
    let prep = prepare(mesh, opts, "mesh")?;
    let (values, stats) = MeshSdf::new(gpu)?.run(&prep)?;
    let g = prep.grid;
    let vol = Volume::new(g.dims, values, "mesh signed distance")?
        .with_geometry([g.spacing; 3], g.origin)?;
    Ok((vol, stats))
}

impl MeshSdf {
    /// Builds `kernels/mesh_sdf.cl` (cached per device) and the scan.
    pub fn new(gpu: Arc<Gpu>) -> Result<MeshSdf> {
        let p = gpu.program(&KERNELS, &build_options())?;
        Ok(MeshSdf {
            scan: Scan::new(gpu.clone())?,
            bin_count: gpu.kernel(&p, "msdf_bin_count")?,
            bin_fill: gpu.kernel(&p, "msdf_bin_fill")?,
            band: gpu.kernel(&p, "msdf_band")?,
            jfa: gpu.kernel(&p, "msdf_jfa")?,
            cross: gpu.kernel(&p, "msdf_cross")?,
            wind: gpu.kernel(&p, "msdf_wind")?,
            finish: gpu.kernel(&p, "msdf_finish")?,
            gpu,
        })
    }

    /// Converts a prepared mesh: the field's samples (x fastest) and stats.
    pub fn run(&mut self, prep: &PreparedMesh) -> Result<(Vec<f32>, MeshSdfStats)> {
        let (v, s, _) = self.run_inner(prep, false)?;
        Ok((v, s))
    }

    /// [`MeshSdf::run`] that also reads back the intermediate buffers.
    pub fn run_traced(
        &mut self,
        prep: &PreparedMesh,
    ) -> Result<(Vec<f32>, MeshSdfStats, MeshSdfTrace)> {
        self.run_inner(prep, true)
    }

    fn run_inner(
        &mut self,
        prep: &PreparedMesh,
        traced: bool,
    ) -> Result<(Vec<f32>, MeshSdfStats, MeshSdfTrace)> {
        let t0 = Instant::now();
        let g = &*self.gpu.clone();
        let grid = prep.grid;
        let n = grid.voxels();
        let ntri = prep.triangles.len();
        let cd = grid.cell_dims();
        let cells = cd[0] * cd[1] * cd[2];
        let entries = prep.bin_entries()?;
        if n > u32::MAX as usize {
            return Err(Error::InvalidArgument(format!(
                "mesh signed distance: {n} voxels exceed the u32 index range"
            )));
        }
        let mut st = MeshSdfStats {
            dims: grid.dims,
            spacing: grid.spacing,
            origin: grid.origin,
            voxels: n,
            triangles: ntri,
            degenerate_faces: prep.degenerate,
            bin_entries: entries,
            ..Default::default()
        };
        st.device_bytes = 28 * n as u64
            + 12 * cells as u64
            + 4 * entries.max(1)
            + 24 * prep.grid_pos.len() as u64
            + 12 * ntri as u64
            + self.scan.scratch_bytes();

        // Inputs.
        let nv = prep.grid_pos.len();
        let mut pos = g.buffer_flags::<f32>(3 * nv, CL_MEM_READ_ONLY)?;
        g.write(&mut pos, prep.grid_pos.as_flattened())?;
        let mut fix = g.buffer_flags::<i32>(3 * nv, CL_MEM_READ_ONLY)?;
        g.write(&mut fix, prep.fixed.as_flattened())?;
        let mut tris = g.buffer_flags::<u32>(3 * ntri, CL_MEM_READ_ONLY)?;
        g.write(&mut tris, prep.triangles.as_flattened())?;

        // Spatial grid of triangles.
        let (cx, cy, cz) = (cd[0] as i32, cd[1] as i32, cd[2] as i32);
        let cell = CELL_VOXELS as f32;
        let mut counts = g.buffer::<u32>(cells)?;
        let offsets = g.buffer::<u32>(cells)?;
        let mut cursor = g.buffer::<u32>(cells)?;
        let list = g.buffer::<u32>(entries as usize)?;
        g.zero(&mut counts, cells)?;
        g.zero(&mut cursor, cells)?;
        let mut ev: Vec<Event> = Vec::new();
        let bin_args = |extra: &[Arg]| {
            let mut a = vec![
                Arg::U32(ntri as u32),
                buf(&tris),
                buf(&pos),
                Arg::F32(BAND_VOXELS),
                Arg::F32(cell),
                Arg::I32(cx),
                Arg::I32(cy),
                Arg::I32(cz),
            ];
            a.extend_from_slice(extra);
            a
        };
        ev.extend(launch(
            g,
            &self.bin_count,
            ntri,
            &bin_args(&[buf(&counts)]),
        )?);
        let total = self.scan.exclusive(&counts, &offsets, cells)?;
        if total != entries {
            return Err(Error::InvalidArgument(format!(
                "mesh signed distance: the device counted {total} grid entries, the host {entries}"
            )));
        }
        ev.extend(launch(
            g,
            &self.bin_fill,
            ntri,
            &bin_args(&[buf(&offsets), buf(&cursor), buf(&list)]),
        )?);
        st.bin_ms = wait_all(&mut ev)? + self.scan.last_ms();

        // Distances: band, then flooding (ping-pong).
        let [nx, ny, nz] = grid.dims.map(|d| d as i32);
        let d2 = [g.buffer::<f32>(n)?, g.buffer::<f32>(n)?];
        let id = [g.buffer::<u32>(n)?, g.buffer::<u32>(n)?];
        ev.extend(launch(
            g,
            &self.band,
            n,
            &[
                Arg::U32(n as u32),
                Arg::I32(nx),
                Arg::I32(ny),
                Arg::I32(CELL_VOXELS as i32),
                Arg::I32(cx),
                Arg::I32(cy),
                buf(&counts),
                buf(&offsets),
                buf(&list),
                buf(&tris),
                buf(&pos),
                buf(&d2[0]),
                buf(&id[0]),
            ],
        )?);
        st.band_ms = wait_all(&mut ev)?;
        let mut trace = MeshSdfTrace::default();
        if traced {
            trace.band = (read_vec(g, &d2[0], n)?, read_vec(g, &id[0], n)?);
        }
        let steps = grid.steps();
        st.jfa_passes = steps.len();
        let mut cur = 0;
        for step in steps {
            ev.extend(launch(
                g,
                &self.jfa,
                n,
                &[
                    Arg::U32(n as u32),
                    Arg::I32(nx),
                    Arg::I32(ny),
                    Arg::I32(nz),
                    Arg::I32(step as i32),
                    Arg::F32(BAND_VOXELS * BAND_VOXELS),
                    buf(&d2[cur]),
                    buf(&id[cur]),
                    buf(&d2[1 - cur]),
                    buf(&id[1 - cur]),
                    buf(&tris),
                    buf(&pos),
                ],
            )?);
            cur = 1 - cur;
        }
        st.jfa_ms = wait_all(&mut ev)?;
        if traced {
            trace.flooded = (read_vec(g, &d2[cur], n)?, read_vec(g, &id[cur], n)?);
        }

        // Sign: six-ray winding sum, one axis at a time into one crossings buffer.
        let mut diff = g.buffer::<i32>(n)?;
        let mut winding = g.buffer::<i32>(n)?;
        g.zero(&mut winding, n)?;
        for axis in 0..3 {
            let (ku, kv) = ((axis + 1) % 3, (axis + 2) % 3);
            let lines = grid.dims[ku] * grid.dims[kv];
            g.zero(&mut diff, n)?;
            let dims = [
                Arg::I32(axis as i32),
                Arg::I32(nx),
                Arg::I32(ny),
                Arg::I32(nz),
            ];
            let mut a = vec![Arg::U32(ntri as u32)];
            a.extend_from_slice(&dims);
            a.extend([buf(&tris), buf(&fix), buf(&diff)]);
            ev.extend(launch(g, &self.cross, ntri, &a)?);
            let mut a = vec![Arg::U32(lines as u32)];
            a.extend_from_slice(&dims);
            a.extend([buf(&diff), buf(&winding)]);
            ev.extend(launch(g, &self.wind, lines, &a)?);
        }
        st.sign_ms = wait_all(&mut ev)?;
        if traced {
            trace.winding = read_vec(g, &winding, n)?;
        }

        let out = g.buffer::<f32>(n)?;
        ev.extend(launch(
            g,
            &self.finish,
            n,
            &[
                Arg::U32(n as u32),
                Arg::F32(grid.spacing as f32),
                buf(&d2[cur]),
                buf(&winding),
                buf(&out),
            ],
        )?);
        st.finish_ms = wait_all(&mut ev)?;
        let values = read_vec(g, &out, n)?;
        st.kernel_ms = st.bin_ms + st.band_ms + st.jfa_ms + st.sign_ms + st.finish_ms;
        st.wall_ms = t0.elapsed().as_secs_f64() * 1e3;
        if let Some(i) = values.iter().position(|v| !v.is_finite()) {
            return Err(Error::input(
                "mesh",
                format!("voxel {i}"),
                "no triangle reached this sample (non-finite distance)",
            ));
        }
        Ok((values, st, trace))
    }
}

/// Waits for `ev` (in order) and returns their summed kernel ms.
fn wait_all(ev: &mut Vec<Event>) -> Result<f64> {
    let mut ms = 0.0;
    for e in ev.drain(..) {
        e.wait().map_err(|e| Error::cl("clWaitForEvents", e))?;
        ms += event_ms(&e);
    }
    Ok(ms)
}

fn read_vec<T: Copy + Default>(g: &Gpu, b: &Buffer<T>, n: usize) -> Result<Vec<T>> {
    let mut v = vec![T::default(); n];
    g.read(b, &mut v)?;
    Ok(v)
}
