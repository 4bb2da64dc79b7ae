//! Host wiring of `kernels/mesh_sdf.cl`: a triangle mesh to a signed
//! distance field (negative inside, world units, on the grid of
//! [`crate::mesh::mesh_sdf::prepare`]), the input the curvature-directed
//! strokes need when they are given a mesh. CPU twin:
//! [`crate::cpu::mesh_sdf`], which matches it bit for bit.
//!
//! Passes: `msdf_clear` → `msdf_band_min` → `msdf_band_id` (exact nearest
//! triangle in the narrow band, per triangle with atomics) → `msdf_seed` →
//! `msdf_jfa` per step (jump flooding of nearest points beyond the band) →
//! `msdf_refine` (exact distance to each voxel's candidate triangle, with a
//! descent across edge-adjacent triangles) → per axis `msdf_cross` +
//! `msdf_wind` (six-ray winding number, Jacobson et al. 2013) →
//! `msdf_finish`. Everything stays on the device until the field is read.
//!
//! Device memory: 48 bytes per voxel (nearest point and triangle twice for
//! the flooding ping-pong, distance, crossings, winding, output), 24 per
//! vertex, 24 per triangle (corners and edge neighbours).

use crate::error::{Error, Result};
use crate::gpu::{Arg, Gpu, buf, event_ms, launch};
use crate::mesh::Mesh;
use crate::mesh::mesh_sdf::prepare;
use crate::spec::mesh_sdf::MsdfKernel;
use crate::spec::mesh_sdf::{BAND_VOXELS, FIX_BITS, MAX_DESCENT, MeshSdfOptions, PreparedMesh};
use crate::spec::timing::{Step, Timing};
use crate::stages::kernel_files;
use crate::volume::Volume;
use opencl3::event::Event;
use opencl3::kernel::Kernel;
use opencl3::memory::{Buffer, CL_MEM_READ_ONLY};
use std::sync::Arc;
use std::time::Instant;

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
    /// Point-triangle distances of the band pass.
    pub band_work: u64,
    /// Jump-flooding passes (steps).
    pub jfa_passes: usize,
    /// Kernel ms per step (`MsdfBand`, `MsdfJfa`, `MsdfRefine`, `MsdfSign`,
    /// `MsdfFinish`), their sum, and the wall ms from the upload to the
    /// field read back (program build excluded).
    pub timing: Timing,
    /// Device bytes allocated.
    pub device_bytes: u64,
}

/// Intermediate results read back for step-by-step comparison with the CPU
/// twin ([`MeshSdf::run_traced`]).
#[derive(Clone, Debug, Default)]
pub struct MeshSdfTrace {
    /// `msdf_band_id`: squared distance (voxels²) and triangle per voxel.
    pub band: (Vec<f32>, Vec<u32>),
    /// After the last `msdf_jfa` pass: nearest point (grid units) and triangle.
    pub flooded: (Vec<[f32; 3]>, Vec<u32>),
    /// `msdf_refine`: squared distance (voxels²) and triangle.
    pub refined: (Vec<f32>, Vec<u32>),
    /// Six-ray winding sum per voxel.
    pub winding: Vec<i32>,
}

/// The program and kernels of the family on one device (built once).
pub struct MeshSdf {
    gpu: Arc<Gpu>,
    clear: Kernel,
    band_min: Kernel,
    band_id: Kernel,
    seed: Kernel,
    jfa: Kernel,
    refine: Kernel,
    cross: Kernel,
    wind: Kernel,
    finish: Kernel,
}

/// The options the kernels are built with: the fixed-point bits. Correctly
/// rounded `f32` division and square root, as in the CPU twin, come with
/// every strict build ([`crate::gpu::FpMode`]).
pub fn build_options() -> String {
    format!("-DSC_FIX_BITS={FIX_BITS}")
}

/// Front door: prepares `mesh` ([`prepare`]), converts it on `gpu` and
/// returns the field as a [`Volume`] in the mesh's world coordinates
/// (negative inside) with the stats.
///
/// # Errors
///
/// Those of [`prepare`] and [`PreparedMesh::band_work`], device errors,
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
    /// Builds `kernels/mesh_sdf.cl` (cached per device).
    pub fn new(gpu: Arc<Gpu>) -> Result<MeshSdf> {
        let p = gpu.program(&kernel_files::MESH_SDF, &build_options())?;
        Ok(MeshSdf {
            clear: gpu.entry(&p, MsdfKernel::Clear)?,
            band_min: gpu.entry(&p, MsdfKernel::BandMin)?,
            band_id: gpu.entry(&p, MsdfKernel::BandId)?,
            seed: gpu.entry(&p, MsdfKernel::Seed)?,
            jfa: gpu.entry(&p, MsdfKernel::Jfa)?,
            refine: gpu.entry(&p, MsdfKernel::Refine)?,
            cross: gpu.entry(&p, MsdfKernel::Cross)?,
            wind: gpu.entry(&p, MsdfKernel::Wind)?,
            finish: gpu.entry(&p, MsdfKernel::Finish)?,
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

    /// Converts `prep`, reading the intermediate buffers back when `traced`.
    fn run_inner(
        &mut self,
        prep: &PreparedMesh,
        traced: bool,
    ) -> Result<(Vec<f32>, MeshSdfStats, MeshSdfTrace)> {
        let t0 = Instant::now();
        let g = &*self.gpu.clone();
        let mut st = stats_of(prep)?;
        let mut c = Conversion::new(self, g, prep)?;
        let n = c.n;
        let mut trace = MeshSdfTrace::default();
        st.timing.add(Step::MsdfBand, c.band()?);
        if traced {
            trace.band = (read_vec(g, &c.d2, n)?, read_vec(g, &c.id[0], n)?);
        }
        st.jfa_passes = prep.grid.steps().len();
        let (ms, cur) = c.flood()?;
        st.timing.add(Step::MsdfJfa, ms);
        if traced {
            let flat: Vec<f32> = read_vec(g, &c.q[cur], 3 * n)?;
            let pts = flat.chunks_exact(3).map(|c| [c[0], c[1], c[2]]).collect();
            trace.flooded = (pts, read_vec(g, &c.id[cur], n)?);
        }
        st.timing.add(Step::MsdfRefine, c.refine(cur)?);
        if traced {
            trace.refined = (read_vec(g, &c.d2, n)?, read_vec(g, &c.id[1 - cur], n)?);
        }
        let (ms, winding) = c.sign()?;
        st.timing.add(Step::MsdfSign, ms);
        if traced {
            trace.winding = read_vec(g, &winding, n)?;
        }
        let (ms, out) = c.finish(&winding)?;
        st.timing.add(Step::MsdfFinish, ms);
        let values = read_vec(g, &out, n)?;
        st.timing.wall_ms = t0.elapsed().as_secs_f64() * 1e3;
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

/// The stats of converting `prep` known before it runs; refuses a grid past
/// the u32 index range.
fn stats_of(prep: &PreparedMesh) -> Result<MeshSdfStats> {
    let grid = prep.grid;
    let n = grid.voxels();
    let ntri = prep.triangles.len();
    let work = prep.band_work()?;
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
        band_work: work,
        ..Default::default()
    };
    st.device_bytes = 48 * n as u64 + 24 * prep.grid_pos.len() as u64 + 24 * ntri as u64;
    Ok(st)
}

/// One conversion: the kernels, the device, the prepared mesh's buffers,
/// the nearest-triangle buffers and the launches not yet waited for; its
/// methods are the passes, in the order they run.
struct Conversion<'a> {
    k: &'a MeshSdf,
    g: &'a Gpu,
    prep: &'a PreparedMesh,
    /// Voxels and triangles.
    n: usize,
    ntri: usize,
    /// Grid positions, fixed-point positions, triangles, edge neighbours.
    pos: Buffer<f32>,
    fix: Buffer<i32>,
    tris: Buffer<u32>,
    adj: Buffer<u32>,
    /// Squared distance, nearest triangle and nearest point per voxel (the
    /// last two twice, for the flooding's ping-pong).
    d2: Buffer<f32>,
    id: [Buffer<u32>; 2],
    q: [Buffer<f32>; 2],
    ev: Vec<Event>,
}

impl<'a> Conversion<'a> {
    /// Uploads `prep` and allocates the nearest-triangle buffers.
    fn new(k: &'a MeshSdf, g: &'a Gpu, prep: &'a PreparedMesh) -> Result<Self> {
        let (n, ntri, nv) = (
            prep.grid.voxels(),
            prep.triangles.len(),
            prep.grid_pos.len(),
        );
        let mut pos = g.buffer_flags::<f32>(3 * nv, CL_MEM_READ_ONLY)?;
        g.write(&mut pos, prep.grid_pos.as_flattened())?;
        let mut fix = g.buffer_flags::<i32>(3 * nv, CL_MEM_READ_ONLY)?;
        g.write(&mut fix, prep.fixed.as_flattened())?;
        let mut tris = g.buffer_flags::<u32>(3 * ntri, CL_MEM_READ_ONLY)?;
        g.write(&mut tris, prep.triangles.as_flattened())?;
        let mut adj = g.buffer_flags::<u32>(3 * ntri, CL_MEM_READ_ONLY)?;
        g.write(&mut adj, prep.adjacent.as_flattened())?;
        Ok(Conversion {
            k,
            g,
            prep,
            n,
            ntri,
            pos,
            fix,
            tris,
            adj,
            d2: g.buffer::<f32>(n)?,
            id: [g.buffer::<u32>(n)?, g.buffer::<u32>(n)?],
            q: [g.buffer::<f32>(3 * n)?, g.buffer::<f32>(3 * n)?],
            ev: Vec::new(),
        })
    }

    /// nx, ny, nz as kernel arguments.
    fn dims(&self) -> [Arg; 3] {
        self.prep.grid.dims.map(|d| Arg::I32(d as i32))
    }

    /// `msdf_clear`, `msdf_band_min`, `msdf_band_id`: the exact nearest
    /// triangle within BAND_VOXELS; returns the kernel ms.
    fn band(&mut self) -> Result<f64> {
        let (g, k, n, ntri) = (self.g, self.k, self.n, self.ntri);
        let (d2, id0) = (buf(&self.d2), buf(&self.id[0]));
        let nu = Arg::U32(n as u32);
        self.ev.extend(launch(g, &k.clear, n, &[nu, d2, id0])?);
        let mut a = vec![Arg::U32(ntri as u32)];
        a.extend_from_slice(&self.dims());
        a.extend([Arg::F32(BAND_VOXELS), buf(&self.tris), buf(&self.pos), d2]);
        self.ev.extend(launch(g, &k.band_min, ntri, &a)?);
        a.push(id0);
        self.ev.extend(launch(g, &k.band_id, ntri, &a)?);
        wait_all(&mut self.ev)
    }

    /// `msdf_seed` and `msdf_jfa` per step: nearest points flooded beyond
    /// the band (ping-pong); returns the kernel ms and the buffers' side
    /// that holds the result.
    fn flood(&mut self) -> Result<(f64, usize)> {
        let (g, k, n, dims) = (self.g, self.k, self.n, self.dims());
        let nu = Arg::U32(n as u32);
        let (id, q) = (&self.id, &self.q);
        let a = [
            nu,
            dims[0],
            dims[1],
            buf(&id[0]),
            buf(&self.tris),
            buf(&self.pos),
            buf(&q[0]),
        ];
        self.ev.extend(launch(g, &k.seed, n, &a)?);
        let mut cur = 0;
        for step in self.prep.grid.steps() {
            let mut a = vec![nu];
            a.extend_from_slice(&dims);
            a.extend([
                Arg::I32(step as i32),
                buf(&q[cur]),
                buf(&id[cur]),
                buf(&q[1 - cur]),
                buf(&id[1 - cur]),
            ]);
            self.ev.extend(launch(g, &k.jfa, n, &a)?);
            cur = 1 - cur;
        }
        Ok((wait_all(&mut self.ev)?, cur))
    }

    /// `msdf_refine`: the exact distance to each voxel's candidate triangle
    /// (side `cur`), with a descent across edge-adjacent triangles, into
    /// the other side; returns the kernel ms.
    fn refine(&mut self, cur: usize) -> Result<f64> {
        let mut a = vec![Arg::U32(self.n as u32)];
        a.extend_from_slice(&self.dims());
        a.extend([
            buf(&self.id[cur]),
            buf(&self.tris),
            buf(&self.pos),
            buf(&self.adj),
            Arg::U32(MAX_DESCENT),
            buf(&self.d2),
            buf(&self.id[1 - cur]),
        ]);
        self.ev.extend(launch(self.g, &self.k.refine, self.n, &a)?);
        wait_all(&mut self.ev)
    }

    /// `msdf_cross` and `msdf_wind` per axis: the six-ray winding sum, one
    /// axis at a time into one crossings buffer; returns the kernel ms and
    /// the sums.
    fn sign(&mut self) -> Result<(f64, Buffer<i32>)> {
        let (g, n, ntri, grid) = (self.g, self.n, self.ntri, self.prep.grid);
        let [nx, ny, nz] = grid.dims.map(|d| d as i32);
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
            a.extend([buf(&self.tris), buf(&self.fix), buf(&diff)]);
            self.ev.extend(launch(g, &self.k.cross, ntri, &a)?);
            let mut a = vec![Arg::U32(lines as u32)];
            a.extend_from_slice(&dims);
            a.extend([buf(&diff), buf(&winding)]);
            self.ev.extend(launch(g, &self.k.wind, lines, &a)?);
        }
        Ok((wait_all(&mut self.ev)?, winding))
    }

    /// `msdf_finish`: the signed distance in world units from the squared
    /// distance and the winding sums; returns the kernel ms and the field.
    fn finish(&mut self, winding: &Buffer<i32>) -> Result<(f64, Buffer<f32>)> {
        let (g, n) = (self.g, self.n);
        let out = g.buffer::<f32>(n)?;
        let a = [
            Arg::U32(n as u32),
            Arg::F32(self.prep.grid.spacing as f32),
            buf(&self.d2),
            buf(winding),
            buf(&out),
        ];
        self.ev.extend(launch(g, &self.k.finish, n, &a)?);
        Ok((wait_all(&mut self.ev)?, out))
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
